#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_multiview : require
// Point-light shadow cubes, all six faces in one pass (--omni-shadow multiview): view i is
// cube face i.
#include "common.glsl"
#include "omni_shadow_vertex.glsl"

void main() {
    out_from_light = omni_from_light();
    gl_Position = omni_face_clip(omni.view_proj, out_from_light, gl_ViewIndex);
}
