// The depth pyramid's layout (depth_pyramid.comp writes it, the late culling phase reads it):
// one storage buffer of floats, level after level. Level L holds the farthest depth over
// 2^(L+1) pixels a side; level 0 is the image size rounded up to powers of two and halved, so
// that every level halves exactly (targets.rs depth_pyramid_shape says the same).

#ifndef MANYLIGHTS_DEPTH_PYRAMID_GLSL
#define MANYLIGHTS_DEPTH_PYRAMID_GLSL

uvec2 pyramid_level_size(uvec2 image, int level) {
    uvec2 pow2 = uvec2(1u) << uvec2(findMSB(max(image, uvec2(2u)) - 1u) + 1);
    return max((pow2 >> 1u) >> uint(level), uvec2(1u));
}

// Where level `level` starts in the buffer.
uint pyramid_level_offset(uvec2 image, int level) {
    uint offset = 0u;
    for (int l = 0; l < level; l++) {
        uvec2 s = pyramid_level_size(image, l);
        offset += s.x * s.y;
    }
    return offset;
}

#endif
