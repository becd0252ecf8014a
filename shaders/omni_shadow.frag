#version 450
#extension GL_GOOGLE_include_directive : require
// Point-light shadow cubes: the depth stored is the distance to the light over its radius
// (linear, so every face and the lookup agree on one scale), not the projection's depth.
#include "common.glsl"

layout(location = 0) in vec3 in_to_light;

layout(push_constant) uniform OmniShadowPushBlock { OmniShadowPush omni; };

void main() {
    gl_FragDepth = length(in_to_light) / omni.light_position_radius.w;
}
