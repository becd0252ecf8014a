#version 450
#extension GL_GOOGLE_include_directive : require
// The sun's shadow map (blinn-phong): depth only, every object, from the light.
#include "common/common.glsl"

layout(location = 0) in vec3 in_position;

layout(push_constant) uniform ShadowPushBlock { ShadowPush shadow; };

void main() {
    gl_Position = shadow.light_view_proj * (shadow.model * vec4(in_position, 1.0));
}
