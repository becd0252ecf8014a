#version 450
#extension GL_GOOGLE_include_directive : require
// The sun's shadow map (blinn-phong), alpha-masked objects: the rasterised depth where the
// mask keeps the point, nothing where it cuts it out (shadow_mask.glsl).
#include "common/common.glsl"
#include "shadows/shadow_mask.glsl"

void main() {
    shadow_mask_test();
}
