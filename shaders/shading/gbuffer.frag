#version 450
#extension GL_GOOGLE_include_directive : require
// The G-buffer pass of the deferred techniques (gbuffer_frag.glsl).
#include "shading/gbuffer_frag.glsl"
