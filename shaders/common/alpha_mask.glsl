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
// block, from the first even byte after its texels; at most ALPHA_CACHE_PAIRS of them.
const uint ALPHA_CACHE_PAIRS = 2048u;

// Where texture `texture_fields`' bounds start (bytes).
uint alpha_bounds_start(uvec4 texture_fields) {
    uint texels = texture_fields.z * texture_fields.w;
    return texture_fields.y + texels + (texels & 1u);
}

#ifdef ALPHA_BOUNDS_CACHE
// A compute raster's copy of one texture's bounds in shared memory: every pixel of a masked
// triangle reads its block's pair, and a read from shared memory keeps the loop from waiting
// on memory at every pixel. From the word holding its first pair; NO_ALPHA_CACHE: none held.
shared uint alpha_cache[ALPHA_CACHE_PAIRS / 2u + 1u];
shared uint alpha_cache_word;
const uint NO_ALPHA_CACHE = 0xffffffffu;

// Copy texture `texture_fields`' bounds into the cache (the whole work group, in uniform
// control flow; `cache` false empties it).
void cache_alpha_bounds(uvec4 texture_fields, bool cache) {
    uint w = texture_fields.z, h = texture_fields.w, side = 1u << ((texture_fields.x >> OBJECT_ALPHA_BLOCK_SHIFT) & 15u);
    uint first = alpha_bounds_start(texture_fields) >> 2u;
    uint words = (alpha_bounds_start(texture_fields) + 2u * ((w + side - 1u) / side) * ((h + side - 1u) / side) + 3u) / 4u - first;
    barrier();
    for (uint i = gl_LocalInvocationIndex; cache && i < words; i += gl_WorkGroupSize.x * gl_WorkGroupSize.y * gl_WorkGroupSize.z) {
        alpha_cache[i] = alpha_bytes[first + i];
    }
    if (gl_LocalInvocationIndex == 0u) {
        alpha_cache_word = cache ? first : NO_ALPHA_CACHE;
    }
    barrier();
}
#endif

// The pair at byte `at` of the alpha-mask buffer: least in the low byte, greatest above.
uint alpha_bounds_pair(uint at) {
#ifdef ALPHA_BOUNDS_CACHE
    if (alpha_cache_word != NO_ALPHA_CACHE) {
        return alpha_cache[(at >> 2u) - alpha_cache_word] >> ((at & 3u) * 8u);
    }
#endif
    return alpha_bytes[at >> 2u] >> ((at & 3u) * 8u);
}

// Whether `factor` × the texture's alpha at `uv` reaches `cutoff`: the bounds of the block
// the point's first tap is in decide where both lie on one side of the cutoff (one read);
// only points near the cut-out's edge are filtered. Keep in sync with alpha_mask.rs
// texture_kept.
bool texture_kept(uvec4 texture_fields, vec2 uv, float factor, float cutoff) {
    uint flags = texture_fields.x;
    int w = int(texture_fields.z), h = int(texture_fields.w);
    vec2 p = uv * vec2(w, h) - 0.5;
    uvec2 f = uvec2(wrap_texels(texture_fields, ivec2((flags & OBJECT_ALPHA_NEAREST) != 0u ? floor(p + 0.5) : floor(p))));
    uint x = f.x, y = f.y;
    uint shift = (flags >> OBJECT_ALPHA_BLOCK_SHIFT) & 15u;
    uint row = (uint(w) + (1u << shift) - 1u) >> shift;
    uint pair = alpha_bounds_pair(alpha_bounds_start(texture_fields) + 2u * ((y >> shift) * row + (x >> shift)));
    if (factor * (float(pair & 0xffu) / 255.0) >= cutoff) {
        return true;
    }
    if (factor * (float((pair >> 8u) & 0xffu) / 255.0) < cutoff) {
        return false;
    }
    return factor * texture_alpha(texture_fields, uv) >= cutoff;
}

// Whether the point at `uv` of the object with ObjectData `alpha` and `alpha_texture` is there.
bool alpha_kept(vec4 alpha, uvec4 alpha_texture, vec2 uv) {
    if ((alpha_texture.x & OBJECT_MASKED) == 0u) {
        return true;
    }
    if ((alpha_texture.x & OBJECT_ALPHA_TEXTURE) != 0u) {
        return texture_kept(alpha_texture, uv, alpha.y, alpha.x);
    }
    return alpha.y >= alpha.x;
}

#endif
