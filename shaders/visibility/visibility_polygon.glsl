// The compute raster's large triangles (docs/DESIGN.md#compute-raster): those whose box is
// wider than the split, or that cross the near plane, clipped and drawn as polygons
// (polygon_raster.glsl) into the 64-bit visibility buffer. The thread that finds one
// (triangle_raster.comp) clips it once into the list of large triangles and lists the
// 64×64-pixel bins of its box; a work group per bin then draws it (triangle_raster_large.comp).
// Past the lists' capacity the finding thread draws it alone. As the pipeline draws: back
// faces culled, depth z/w interpolated linearly in the image, LESS against what is there by
// the same atomic min as the small triangles — but both faces of a double-sided object's
// triangle, and only the pixels its alpha mask keeps (raster_surface.glsl).
// The includer declares `frame` (FrameBlock), `visibility_depth[]` (VisibilityDepthBuffer)
// and `large_triangles[]` (LargeTriangleBuffer), and includes alpha_mask.glsl.

#ifndef MANYLIGHTS_VISIBILITY_POLYGON_GLSL
#define MANYLIGHTS_VISIBILITY_POLYGON_GLSL

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

#include "visibility/visibility_samples.glsl"
#include "visibility/polygon_raster.glsl"
#include "visibility/raster_surface.glsl"

// Bins of the large triangles: squares of this many pixels.
const int BIN = 64;
// A listed bin: (large triangle, bin x | bin y << 16); this where the thread that found the
// triangle drew it itself (the lists were full) and left the entry unused.
const uint NO_BIN = 0xffffffffu;

// LESS against what sample s of `pixel` holds (the depth << 32 | id of the nearest triangle
// so far; all ones, above every value, where nothing is) and against the far plane.
void keep_nearest_id(ivec2 pixel, uint s, float depth, uint id) {
    if (depth < 1.0) {
        uint64_t value = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(id);
        // No read first to skip the atomic where the sample holds a nearer value already: on
        // the H200 that made the bench scene's raster 1.2x (one sample) to 1.6x (eight)
        // slower — an atomic whose result is unused costs the thread no wait, a read does.
        atomicMin(visibility_depth[sample_slot(pixel, s, frame.viewport.x)], value);
    }
}

// The triangle's polygon in the image, each corner's depth z/w in q.x.
Polygon visibility_polygon(vec4 a, vec4 b, vec4 c) {
    Polygon p = clipped_polygon(a, b, c, vec3(a.z, 0.0, 0.0), vec3(b.z, 0.0, 0.0), vec3(c.z, 0.0, 0.0), vec2(frame.viewport.xy));
    for (int i = 0; i < p.count; i++) {
        p.q[i].x *= p.q[i].w;
    }
    return p;
}

// The polygon as the large-triangle list keeps it, with its instance's INSTANCE_* `flags`,
// its `object` and its surface test.
void store_large(uint at, Polygon p, uint id, uint flags, uint object, SurfaceTest s) {
    large_triangles[at].head = uvec4(uint(p.count), id, s.masked ? object : NOT_MASKED, flags);
    if (s.masked) {
        large_triangles[at].surface_clip[0] = s.clip[0];
        large_triangles[at].surface_clip[1] = s.clip[1];
        large_triangles[at].surface_clip[2] = s.clip[2];
        large_triangles[at].surface_uv[0] = vec4(s.uv[0], s.uv[1]);
        large_triangles[at].surface_uv[1] = vec4(s.uv[2], 0.0, 0.0);
    }
    for (int i = 0; i < MAX_POLYGON; i += 2) {
        ivec2 s0 = i < p.count ? ivec2(p.s[i]) : ivec2(0), s1 = i + 1 < p.count ? ivec2(p.s[i + 1]) : ivec2(0);
        large_triangles[at].corners[i >> 1] = ivec4(s0, s1);
    }
    large_triangles[at].depths[0] = vec4(p.q[0].x, p.q[1].x, p.q[2].x, p.q[3].x);
    large_triangles[at].depths[1] = vec4(p.q[4].x, p.q[5].x, p.q[6].x, p.q[7].x);
}

// Corner k of listed triangle `at`: snapped position, depth in q.x.
i64vec2 large_corner(uint at, int k) {
    ivec4 pair = large_triangles[at].corners[k >> 1];
    return i64vec2((k & 1) == 0 ? pair.xy : pair.zw);
}

vec4 large_depth(uint at, int k) {
    return vec4(large_triangles[at].depths[k >> 2][k & 3], 0.0, 0.0, 0.0);
}

#ifdef MANYLIGHTS_LAYER_CANDIDATES_GLSL
// A transparent core's alpha at the point `xy` (in pixels) as the raster needs it
// (core_sample_alpha).
float core_alpha_at(SurfaceTest s, vec2 xy, vec2 size) {
    vec3 l = clip_barycentrics(s.clip[0], s.clip[1], s.clip[2], xy / size * 2.0 - 1.0);
    vec2 uv = l.x * s.uv[0] + l.y * s.uv[1] + l.z * s.uv[2];
    return core_sample_alpha(s.alpha, s.alpha_texture, uv, core_sample_verdict(s.alpha, s.alpha_texture, uv));
}
#endif

// Sample k of every `step`-th pixel of each row of [from, to] (from from.x on) that the fan
// triangle covers (and `s` keeps) drawn with visibility id `id`, the edge functions stepped
// from pixel to pixel (exact: integers); returns the samples covered. Where `listing`, a
// transparent core's: its soft samples listed for the layers (layer_candidates.glsl).
uint fan_samples(FanTriangle t, ivec2 from, ivec2 to, int step, uint k, uint id, SurfaceTest s, bool listing) {
    // Per sub-pixel to the right and down, each edge function changes by −d.y and d.x.
    i64vec3 unit_x = -i64vec3(t.c.y - t.b.y, t.a.y - t.c.y, t.b.y - t.a.y);
    i64vec3 unit_y = i64vec3(t.c.x - t.b.x, t.a.x - t.c.x, t.b.x - t.a.x);
    i64vec3 step_x = int64_t(256 * step) * unit_x, step_y = 256l * unit_y;
    // From the first pixel's centre to its sample k.
    i64vec3 row;
    fan_covers(t, from, row);
    ivec2 offset = sample_offset(k) - 128;
    row += int64_t(offset.x) * unit_x + int64_t(offset.y) * unit_y;
    i64vec3 bias = i64vec3(t.bias);
    vec3 z = vec3(t.qa.x, t.qb.x, t.qc.x);
    vec2 size = vec2(frame.viewport.xy);
    uint covered = 0u;
    for (int y = from.y; y <= to.y; y++, row += step_y) {
        i64vec3 w = row;
        for (int x = from.x; x <= to.x; x += step, w += step_x) {
            if (any(lessThan(w - bias, i64vec3(0)))) {
                continue;
            }
            vec3 weights = vec3(w);
            float depth = dot(weights, z) / (weights.x + weights.y + weights.z);
            vec2 xy = vec2(x, y) + vec2(sample_offset(k)) / SUBPIXEL;
            bool kept;
#ifdef MANYLIGHTS_LAYER_CANDIDATES_GLSL
            if (listing) {
                // A transparent core's sample: drawn where its alpha is 1; where between,
                // listed for the layers (by the soft lanes alone).
                float alpha = core_alpha_at(s, xy, size);
                kept = alpha >= 1.0;
                if (!kept && soft_in_front(alpha, ivec2(x, y), k, depth)) {
                    list_soft_sample(true, layer_candidate(k, ivec2(x, y), id, depth));
                }
            } else
#endif
            {
                kept = surface_kept_at(s, xy, size);
            }
            if (kept) {
                covered++;
                keep_nearest_id(ivec2(x, y), k, depth, id);
            }
        }
    }
    return covered;
}

// The whole polygon by this thread alone, over each fan triangle's box (both faces where
// `both_faces`); returns the pixels covered.
uint raster_polygon_alone(Polygon p, uint id, bool both_faces, SurfaceTest s) {
    uint covered = 0u;
    for (int f = 1; f + 1 < p.count; f++) {
        FanTriangle t;
        if (fan_triangle(p.s[0], p.s[f], p.s[f + 1], p.q[0], p.q[f], p.q[f + 1], ivec2(frame.viewport.xy), both_faces, t)) {
            for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
                covered += fan_samples(t, t.first, t.last, 1, k, id, s, false);
            }
        }
    }
    return covered;
}

// The surface test of listed triangle `at` (the includer declares `objects[]`).
SurfaceTest large_surface(uint at, uint object) {
    SurfaceTest s = no_surface_test();
    if (object != NOT_MASKED) {
        vec4 uv = large_triangles[at].surface_uv[0];
        uvec4 alpha_texture = objects[object].alpha_texture;
        s = masked_surface(raster_alpha(objects[object].alpha, alpha_texture.x), alpha_texture, large_triangles[at].surface_clip[0],
                           large_triangles[at].surface_clip[1], large_triangles[at].surface_clip[2], uv.xy, uv.zw,
                           large_triangles[at].surface_uv[1].xy);
    }
    return s;
}

#endif
