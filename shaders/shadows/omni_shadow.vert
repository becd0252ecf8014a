#version 450
#extension GL_GOOGLE_include_directive : require
// Point-light shadow cubes, one face per pass (--omni-shadow copy|direct): the face's
// view-projection comes by push constant, as in the classic copy method
// (docs/DESIGN.md#point-light-shadows).
#include "shadows/omni_shadow_vertex.glsl"
