#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(push_constant) uniform PushBlock { ObjectPush object; };

layout(location = 0) out vec3 out_world_pos;
layout(location = 1) out vec3 out_normal;

void main() {
    vec3 world = in_position * object.position_scale.w + object.position_scale.xyz;
    out_world_pos = world;
    // Objects only translate and scale uniformly, so the normal is unchanged.
    out_normal = in_normal;
    gl_Position = frame.proj * frame.view * vec4(world, 1.0);
}
