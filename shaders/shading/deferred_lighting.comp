#version 450
#extension GL_GOOGLE_include_directive : require
// deferred-compute's lighting, into the colour target (deferred_lighting.glsl).
#include "shading/deferred_lighting.glsl"
