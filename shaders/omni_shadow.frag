#version 450
#extension GL_GOOGLE_include_directive : require
// Point-light shadow cubes: the depth stored is the distance to the light over its radius
// (linear, so every face and the lookup agree on one scale), not the projection's depth.
#include "common.glsl"

layout(location = 0) in vec3 in_from_light; // in radii

void main() {
    gl_FragDepth = length(in_from_light);
}
