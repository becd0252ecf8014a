// Point-light shadow cubes, the fragment shaders' body: the depth stored is the distance to the
// light over its radius (linear, so every face and the lookup agree on one scale), not the
// projection's depth. With OMNI_SHADOW_MASKED (alpha-masked objects' pipeline) only where the
// mask keeps the point (shadow_mask.glsl).

#include "common/common.glsl"
#ifdef OMNI_SHADOW_MASKED
#include "shadows/shadow_mask.glsl"
#endif

layout(location = 0) in vec3 in_from_light; // in radii

void main() {
#ifdef OMNI_SHADOW_MASKED
    shadow_mask_test();
#endif
    gl_FragDepth = length(in_from_light);
}
