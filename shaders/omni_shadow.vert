#version 450
#extension GL_GOOGLE_include_directive : require
// Point-light shadow cubes, one face per pass (--omni-shadow copy|direct): the face's
// view-projection comes by push constant, as in the classic copy method
// (docs/DESIGN.md#point-light-shadows).
#include "common.glsl"
#include "omni_shadow_vertex.glsl"

void main() {
    out_from_light = omni_from_light();
    gl_Position = omni.view_proj * vec4(out_from_light, 1.0);
}
