#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_ARB_shader_viewport_layer_array : require
// Point-light shadow cubes, all six faces in one pass (--omni-shadow layered): each draw has
// six instances, instance i renders face i into layer i of the light's six.
#define OMNI_LAYERED
#include "shadows/omni_shadow_vertex.glsl"
