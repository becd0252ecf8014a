#version 450
#extension GL_GOOGLE_include_directive : require
// Lighting from the visibility buffer as the compute raster's 64-bit buffer, into linear HDR for the transparent resolve.
#define LINEAR_OUTPUT 1
#include "visibility/raster_buffer_lighting.glsl"
