#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_ARB_shader_viewport_layer_array : require
// omni_shadow_layered.vert for alpha-masked objects.
#define OMNI_LAYERED
#define OMNI_SHADOW_MASKED
#include "shadows/omni_shadow_vertex.glsl"
