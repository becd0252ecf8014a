#version 450
#extension GL_GOOGLE_include_directive : require
// The visibility raster in scenes with masked or double-sided objects (visibility_surface.glsl).
#define SURFACE_TESTS 1
#include "visibility/visibility_frag.glsl"
