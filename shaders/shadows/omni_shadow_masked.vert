#version 450
#extension GL_GOOGLE_include_directive : require
// omni_shadow.vert (copy, direct) for alpha-masked objects.
#define OMNI_SHADOW_MASKED
#include "shadows/omni_shadow_vertex.glsl"
