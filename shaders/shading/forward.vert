#version 450
#extension GL_GOOGLE_include_directive : require
#include "common/common.glsl"
#include "common/scene_bindings.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_tangent;

layout(push_constant) uniform PushBlock { ObjectPush object; };

layout(location = 0) out vec3 out_world_pos;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;
layout(location = 3) out vec4 out_tangent;

void main() {
    ObjectData o = objects[object.ids.x];
    vec3 world = (o.model * vec4(in_position, 1.0)).xyz;
    out_world_pos = world;
    // Normals by the inverse transpose (uneven scales); tangents lie in the surface, so the
    // model matrix carries them (surface.glsl makes the frame orthonormal again).
    out_normal = mat3(o.normal_matrix) * in_normal;
    out_uv = transform_uv(o.uv_transform, in_uv);
    out_tangent = vec4(mat3(o.model) * in_tangent.xyz, in_tangent.w);
    gl_Position = frame.proj * frame.view * vec4(world, 1.0);
}
