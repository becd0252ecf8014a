#version 450
#extension GL_GOOGLE_include_directive : require
// deferred-compute's lighting into linear HDR, for the transparent resolve
// (deferred_lighting.glsl, compute_shading.glsl).
#define LINEAR_OUTPUT 1
#include "shading/deferred_lighting.glsl"
