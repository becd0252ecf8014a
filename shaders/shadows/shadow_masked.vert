#version 450
#extension GL_GOOGLE_include_directive : require
// The sun's shadow map (blinn-phong), alpha-masked objects: shadow.vert's position, and the
// texture coordinates for the mask (shadow_mask.glsl).
#include "common/common.glsl"
#define SHADOW_MASK_VERTEX
#include "shadows/shadow_mask.glsl"

layout(location = 0) in vec3 in_position;

void main() {
    gl_Position = shadow_mask.view_proj * vec4(shadow_mask_model(in_position), 1.0);
}
