// Alpha masks (ml-cpu alpha_mask.rs): whether a point of a masked object is there. Every pass
// that decides coverage — the fragment shaders and the compute rasterisers alike — asks
// `alpha_kept`, which filters the alpha of the object's base colour texture by hand from one
// buffer (its base level, bilinear or nearest, with its wrap modes), so all of them cut the same
// shape. Needs common.glsl; the includer defines ALPHA_MASK_BINDING, its set-0 binding.

#ifndef MANYLIGHTS_ALPHA_MASK_GLSL
#define MANYLIGHTS_ALPHA_MASK_GLSL

// The alpha of every texture a masked object cuts with, a byte a texel, four to a word.
layout(std430, set = 0, binding = ALPHA_MASK_BINDING) readonly buffer AlphaMaskBuffer { uint alpha_bytes[]; };

// i modulo n in [0, n) for n > 0 (GLSL's % is undefined for a negative operand; floats are
// exact for the sizes and offsets a texture has, and cheaper than an integer division).
int floor_mod(int i, int n) {
    // Powers of two, most textures' sizes: a mask (two's complement keeps it right for i < 0).
    // A branch, not a select: the division is not computed where the mask does.
    if ((n & (n - 1)) == 0) {
        return i & (n - 1);
    }
    return int(mod(float(i), float(n)));
}

// Texel i of a row or column of `size` under wrap mode `mode` (0 repeat, 1 mirrored repeat,
// 2 clamp). Keep in sync with alpha_mask.rs wrap_texel.
int wrap_texel(int i, int size, uint mode) {
    if (mode == 0u) {
        return floor_mod(i, size);
    }
    if (mode == 1u) {
        int m = floor_mod(i, 2 * size);
        return m < size ? m : 2 * size - 1 - m;
    }
    return clamp(i, 0, size - 1);
}

// The alpha of texel (x, y), both already wrapped.
float alpha_texel(uvec4 texture_fields, int x, int y) {
    uint at = texture_fields.y + uint(y) * texture_fields.z + uint(x);
    return float((alpha_bytes[at >> 2u] >> ((at & 3u) * 8u)) & 0xffu) / 255.0;
}

// Texel coordinates `t` wrapped as the texture wraps.
ivec2 wrap_texels(uvec4 texture_fields, ivec2 t) {
    uint flags = texture_fields.x;
    return ivec2(wrap_texel(t.x, int(texture_fields.z), (flags >> OBJECT_ALPHA_WRAP_SHIFT) & 3u),
                 wrap_texel(t.y, int(texture_fields.w), (flags >> (OBJECT_ALPHA_WRAP_SHIFT + 2u)) & 3u));
}

// The alpha texture at `uv`. Keep in sync with alpha_mask.rs texture_alpha.
float texture_alpha(uvec4 texture_fields, vec2 uv) {
    vec2 p = uv * vec2(texture_fields.zw) - 0.5;
    if ((texture_fields.x & OBJECT_ALPHA_NEAREST) != 0u) {
        ivec2 n = wrap_texels(texture_fields, ivec2(floor(p + 0.5)));
        return alpha_texel(texture_fields, n.x, n.y);
    }
    vec2 f0 = floor(p);
    vec2 f = p - f0;
    ivec2 t0 = wrap_texels(texture_fields, ivec2(f0)), t1 = wrap_texels(texture_fields, ivec2(f0) + 1);
    float top = alpha_texel(texture_fields, t0.x, t0.y) * (1.0 - f.x) + alpha_texel(texture_fields, t1.x, t0.y) * f.x;
    float bottom = alpha_texel(texture_fields, t0.x, t1.y) * (1.0 - f.x) + alpha_texel(texture_fields, t1.x, t1.y) * f.x;
    return top * (1.0 - f.y) + bottom * f.y;
}

// The alpha bounds of a texture's blocks (alpha_mask.rs): a byte pair (least, greatest) per
// block, from the first even byte after its texels.

// Where texture `texture_fields`' bounds start (bytes).
uint alpha_bounds_start(uvec4 texture_fields) {
    uint texels = texture_fields.z * texture_fields.w;
    return texture_fields.y + texels + (texels & 1u);
}

// The pair at byte `at` of the alpha-mask buffer: least in the low byte, greatest above.
uint alpha_bounds_pair(uint at) {
    return alpha_bytes[at >> 2u] >> ((at & 3u) * 8u);
}

// The bounds of the block the first tap of `uv` is in (the pair: least alpha in the low byte,
// greatest above; they hold every tap the filter takes there).
uint texture_bounds_at(uvec4 texture_fields, vec2 uv) {
    uint flags = texture_fields.x;
    int w = int(texture_fields.z), h = int(texture_fields.w);
    vec2 p = uv * vec2(w, h) - 0.5;
    uvec2 f = uvec2(wrap_texels(texture_fields, ivec2((flags & OBJECT_ALPHA_NEAREST) != 0u ? floor(p + 0.5) : floor(p))));
    uint shift = (flags >> OBJECT_ALPHA_BLOCK_SHIFT) & 15u;
    uint row = (uint(w) + (1u << shift) - 1u) >> shift;
    return alpha_bounds_pair(alpha_bounds_start(texture_fields) + 2u * ((f.y >> shift) * row + (f.x >> shift)));
}

// What a point's block bounds say of it: dropped, kept, or filter it (alpha_verdict).
const uint ALPHA_DROPPED = 0u;
const uint ALPHA_KEPT = 1u;
const uint ALPHA_FILTER = 2u;

// Whether `factor` × the texture's alpha at `uv` reaches `cutoff`, as far as the bounds of the
// block the point's first tap is in decide (one read): ALPHA_FILTER where they lie on both
// sides of the cutoff, which happens only near the cut-out's edge. With alpha_filtered_kept,
// keep in sync with alpha_mask.rs texture_kept.
uint texture_bounds_verdict(uvec4 texture_fields, vec2 uv, float factor, float cutoff) {
    uint pair = texture_bounds_at(texture_fields, uv);
    if (factor * (float(pair & 0xffu) / 255.0) >= cutoff) {
        return ALPHA_KEPT;
    }
    if (factor * (float((pair >> 8u) & 0xffu) / 255.0) < cutoff) {
        return ALPHA_DROPPED;
    }
    return ALPHA_FILTER;
}

// alpha_kept's answer as far as one read decides: ALPHA_FILTER where only
// `alpha_filtered_kept` can tell.
uint alpha_verdict(vec4 alpha, uvec4 alpha_texture, vec2 uv) {
    if ((alpha_texture.x & OBJECT_MASKED) == 0u) {
        return ALPHA_KEPT;
    }
    if ((alpha_texture.x & OBJECT_ALPHA_TEXTURE) != 0u) {
        return texture_bounds_verdict(alpha_texture, uv, alpha.y, alpha.x);
    }
    return alpha.y >= alpha.x ? ALPHA_KEPT : ALPHA_DROPPED;
}

// alpha_kept where alpha_verdict said ALPHA_FILTER.
bool alpha_filtered_kept(vec4 alpha, uvec4 alpha_texture, vec2 uv) {
    return alpha.y * texture_alpha(alpha_texture, uv) >= alpha.x;
}

// Whether the point at `uv` of the object with ObjectData `alpha` and `alpha_texture` is there.
bool alpha_kept(vec4 alpha, uvec4 alpha_texture, vec2 uv) {
    uint verdict = alpha_verdict(alpha, alpha_texture, uv);
    if (verdict != ALPHA_FILTER) {
        return verdict == ALPHA_KEPT;
    }
    return alpha_filtered_kept(alpha, alpha_texture, uv);
}

#endif
