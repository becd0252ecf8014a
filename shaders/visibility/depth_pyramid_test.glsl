// Occlusion tests against the depth pyramid (depth_pyramid.glsl), for the passes that read it:
// the late culling phase (meshlet_cull.glsl) and the transparent layers' build
// (layer_triangles.glsl). The includer declares the pyramid as `depth_pyramid[]`.

#ifndef MANYLIGHTS_DEPTH_PYRAMID_TEST_GLSL
#define MANYLIGHTS_DEPTH_PYRAMID_TEST_GLSL

#include "visibility/depth_pyramid.glsl"

// The farthest depth the pyramid of an `image`-sized frame (`levels` levels) holds over the
// pixels p0 to p1 (inclusive, within the image): at the level where they span at most 2
// texels each way (level L's texels cover 2^(L+1) pixels a side).
float pyramid_farthest(uvec2 image, int levels, ivec2 p0, ivec2 p1) {
    ivec2 span = p1 - p0;
    int level = clamp(findMSB(max(span.x, span.y)), 0, levels - 1);
    uvec2 texels = pyramid_level_size(image, level);
    uint base = pyramid_level_offset(image, level);
    uvec2 t0 = uvec2(p0) >> uint(level + 1), t1 = min(uvec2(p1) >> uint(level + 1), texels - 1u);
    float farthest = 0.0;
    for (uint y = t0.y; y <= t1.y; y++) {
        for (uint x = t0.x; x <= t1.x; x++) {
            farthest = max(farthest, depth_pyramid[base + y * texels.x + x]);
        }
    }
    return farthest;
}

// The levels of an `image`-sized frame's pyramid (targets.rs depth_pyramid_shape).
int pyramid_levels(uvec2 image) {
    uvec2 base = pyramid_level_size(image, 0);
    return findMSB(max(base.x, base.y)) + 1;
}

#endif
