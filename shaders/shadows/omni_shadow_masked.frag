#version 450
#extension GL_GOOGLE_include_directive : require
// Point-light shadow cubes, alpha-masked objects: omni_shadow.frag where the mask keeps the
// point (shadow_mask.glsl).
#define OMNI_SHADOW_MASKED
#include "shadows/omni_shadow_frag.glsl"
