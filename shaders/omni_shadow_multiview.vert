#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_multiview : require
// Point-light shadow cubes, all six faces in one pass (--omni-shadow multiview): view i is
// cube face i, turned by the face's axes (ml_cpu::omni_shadow::face_axes) and projected by
// the push constant's projection.
#include "common.glsl"
#include "omni_shadow_vertex.glsl"

// Forward and up of each face: +X, −X, +Y, −Y, +Z, −Z (seed 003's list).
const vec3 FACE_FORWARD[6] = vec3[](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1));
const vec3 FACE_UP[6] = vec3[](vec3(0, -1, 0), vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1), vec3(0, -1, 0), vec3(0, -1, 0));

void main() {
    vec3 world = omni_world_position();
    vec3 rel = world - omni.light_position_radius.xyz;
    out_to_light = rel;
    // look_at_rh's rows: side = forward × up, up' = side × forward, −forward.
    vec3 f = FACE_FORWARD[gl_ViewIndex];
    vec3 s = normalize(cross(f, FACE_UP[gl_ViewIndex]));
    vec3 u = cross(s, f);
    gl_Position = omni.view_proj * vec4(dot(s, rel), dot(u, rel), -dot(f, rel), 1.0);
}
