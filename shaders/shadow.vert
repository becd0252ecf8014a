#version 450
#extension GL_GOOGLE_include_directive : require
// The sun's shadow map (blinn-phong): depth only, every object, from the light.
#include "common.glsl"

layout(location = 0) in vec3 in_position;

layout(push_constant) uniform PushBlock {
    ObjectPush object;
    mat4 light_view_proj;
};

void main() {
    vec3 world = in_position * object.position_scale.w + object.position_scale.xyz;
    gl_Position = light_view_proj * vec4(world, 1.0);
}
