#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_multiview : require
// omni_shadow_multiview.vert for alpha-masked objects.
#define OMNI_MULTIVIEW
#define OMNI_SHADOW_MASKED
#include "shadows/omni_shadow_vertex.glsl"
