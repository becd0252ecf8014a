#version 450
#extension GL_GOOGLE_include_directive : require
// Lighting from the visibility buffer as the hardware raster's images, into the colour target.
#include "visibility/raster_image_lighting.glsl"
