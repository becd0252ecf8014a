#version 450
#extension GL_GOOGLE_include_directive : require
// deferred-compute's lighting with anti-aliasing: each pixel resolved from the multisampled
// G-buffer into the colour target (deferred_lighting.glsl, gbuffer_samples.glsl).
#define MULTISAMPLED 1
#include "shading/deferred_lighting.glsl"
