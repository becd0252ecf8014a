#version 450
#extension GL_GOOGLE_include_directive : require
// Point-light shadow cubes, one face per pass (--omni-shadow copy|direct): the face's
// view-projection comes by push constant, as in seed 003.
#include "common.glsl"
#include "omni_shadow_vertex.glsl"

void main() {
    vec3 world = omni_world_position();
    out_to_light = world - omni.light_position_radius.xyz;
    gl_Position = omni.view_proj * vec4(world, 1.0);
}
