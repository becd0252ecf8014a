#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_multiview : require
// Point-light shadow cubes, all six faces in one pass (--omni-shadow multiview): view i is
// cube face i.
#define OMNI_MULTIVIEW
#include "shadows/omni_shadow_vertex.glsl"
