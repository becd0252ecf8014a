#version 450
#extension GL_GOOGLE_include_directive : require
// Lighting from the visibility buffer as the compute raster's 64-bit buffer, anti-aliased,
// into the colour target, each surface's linear colour kept for the transparent layers'
// blend (transparent_blend_samples.comp).
#define LAYERED_SAMPLES 1
#include "visibility/raster_buffer_lighting.glsl"
