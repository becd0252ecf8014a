#version 450
#extension GL_GOOGLE_include_directive : require
// The sun's shadow map (blinn-phong): depth only, every object, from the light.
#include "common.glsl"

layout(location = 0) in vec3 in_position;

layout(push_constant) uniform ShadowPushBlock { ShadowPush shadow; };

void main() {
    vec3 world = in_position * shadow.object.position_scale.w + shadow.object.position_scale.xyz;
    gl_Position = shadow.light_view_proj * vec4(world, 1.0);
}
