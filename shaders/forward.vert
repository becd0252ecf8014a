#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_tangent;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(push_constant) uniform PushBlock { ObjectPush object; };

layout(location = 0) out vec3 out_world_pos;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;
layout(location = 3) out vec4 out_tangent;

void main() {
    vec3 world = in_position * object.position_scale.w + object.position_scale.xyz;
    out_world_pos = world;
    // Objects only translate and scale uniformly, so normal and tangent are unchanged.
    out_normal = in_normal;
    out_uv = in_uv;
    out_tangent = in_tangent;
    gl_Position = frame.proj * frame.view * vec4(world, 1.0);
}
