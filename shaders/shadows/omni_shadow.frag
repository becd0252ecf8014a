#version 450
#extension GL_GOOGLE_include_directive : require
// Point-light shadow cubes: the distance to the light over its radius (omni_shadow_frag.glsl).
#include "shadows/omni_shadow_frag.glsl"
