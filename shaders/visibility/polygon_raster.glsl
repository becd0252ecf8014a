// Large triangles in the compute rasters (docs/DESIGN.md#compute-raster): a triangle too big
// for one thread, or crossing the near plane, is clipped as the hardware clips it — against
// the near plane, and against a guard band far outside the image — and the convex polygon
// left is drawn as a fan of triangles over the pixels of its box, by Vulkan's rules as in
// raster_rules.glsl but with 64-bit edge functions (a guard-band-sized triangle's products
// need more than 32 bits). The visibility raster (visibility_polygon.glsl) and the shadow
// raster (omni_raster.glsl) draw with it; what a pixel gets is theirs to say.

#ifndef MANYLIGHTS_POLYGON_RASTER_GLSL
#define MANYLIGHTS_POLYGON_RASTER_GLSL

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "visibility/raster_rules.glsl"

// Where clipping against the sides begins: |x|, |y| ≤ GUARD · w, a band 1.5 images wide
// around the image that keeps every snapped coordinate (and the edge functions' products) in
// range. Nothing inside the image moves: what is clipped there lies outside it.
const float GUARD = 4.0;

const int MAX_POLYGON = 8; // a triangle clipped by five planes

int64_t edge_function64(i64vec2 s, i64vec2 e, i64vec2 p) {
    i64vec2 d = e - s;
    return d.x * (p.y - s.y) - d.y * (p.x - s.x);
}

// Clip the triangle (clip-space corners, an attribute per corner in q.xyz) against the near
// plane and the guard band; `count` corners of the convex polygon left. A new corner on an
// edge is found from the edge's inside end, whichever way the edge is walked: two triangles
// sharing that edge get the same corner, so they stay watertight. The attribute is
// interpolated linearly in clip space, as the position is.
int clip_polygon(inout vec4 clip[MAX_POLYGON], inout vec4 q[MAX_POLYGON]) {
    const vec4 planes[5] = vec4[5](vec4(0, 0, 1, 0), vec4(-1, 0, 0, GUARD), vec4(1, 0, 0, GUARD), vec4(0, -1, 0, GUARD), vec4(0, 1, 0, GUARD));
    int count = 3;
    for (int p = 0; p < 5; p++) {
        vec4 in_clip[MAX_POLYGON] = clip;
        vec4 in_q[MAX_POLYGON] = q;
        int kept = 0;
        for (int i = 0; i < count; i++) {
            int j = i + 1 == count ? 0 : i + 1;
            float di = dot(planes[p], in_clip[i]), dj = dot(planes[p], in_clip[j]);
            if (di >= 0.0) {
                clip[kept] = in_clip[i];
                q[kept] = in_q[i];
                kept++;
            }
            if ((di >= 0.0) != (dj >= 0.0)) {
                int inside = di >= 0.0 ? i : j, outside = di >= 0.0 ? j : i;
                float d_in = di >= 0.0 ? di : dj, d_out = di >= 0.0 ? dj : di;
                float t = d_in / (d_in - d_out);
                clip[kept] = mix(in_clip[inside], in_clip[outside], t);
                q[kept] = vec4(mix(in_q[inside].xyz, in_q[outside].xyz, t), 0.0);
                kept++;
            }
        }
        count = kept;
        if (count < 3) {
            return 0;
        }
    }
    return count;
}

// A large triangle's clipped polygon: its corners snapped to the sub-pixel grid, their
// attributes (q.xyz) and 1 / clip w (q.w), drawn as the fan (0, k, k + 1).
struct Polygon {
    int count;
    i64vec2 s[MAX_POLYGON];
    vec4 q[MAX_POLYGON];
};

// The polygon of the triangle with clip-space corners ca, cb, cc and attributes ra, rb, rc
// in an image of `size` pixels.
Polygon clipped_polygon(vec4 ca, vec4 cb, vec4 cc, vec3 ra, vec3 rb, vec3 rc, vec2 size) {
    vec4 clip[MAX_POLYGON];
    Polygon p;
    clip[0] = ca;
    clip[1] = cb;
    clip[2] = cc;
    p.q[0] = vec4(ra, 0.0);
    p.q[1] = vec4(rb, 0.0);
    p.q[2] = vec4(rc, 0.0);
    // Most large triangles lie inside every plane: nothing to clip.
    bool inside = true;
    for (int i = 0; i < 3; i++) {
        vec4 v = clip[i];
        inside = inside && v.z >= 0.0 && abs(v.x) <= GUARD * v.w && abs(v.y) <= GUARD * v.w;
    }
    p.count = inside ? 3 : clip_polygon(clip, p.q);
    for (int i = 0; i < p.count; i++) {
        p.s[i] = i64vec2(ivec2(roundEven(viewport_xy(clip[i], size) * SUBPIXEL)));
        p.q[i].w = 1.0 / clip[i].w;
    }
    return p;
}

// One triangle of a polygon's fan, set up for its pixels: corners ordered so the interior is
// on every edge's positive side, the fill rule's biases, the pixel centres in its box.
struct FanTriangle {
    i64vec2 a, b, c;
    vec4 qa, qb, qc;
    ivec3 bias;
    ivec2 first, last;
};

// The fan triangle with corners (a, b, c), their q, in an image of `size` pixels; false if
// it covers no pixel centre (zero area, its box misses the image, or a back face — clockwise,
// y down — unless `both_faces`).
bool fan_triangle(i64vec2 a, i64vec2 b, i64vec2 c, vec4 qa, vec4 qb, vec4 qc, ivec2 size, bool both_faces, out FanTriangle t) {
    t.a = a;
    t.b = b;
    t.c = c;
    t.qa = qa;
    t.qb = qb;
    t.qc = qc;
    int64_t area = (t.b.x - t.a.x) * (t.c.y - t.a.y) - (t.b.y - t.a.y) * (t.c.x - t.a.x);
    // Front faces have a negative area (raster_rules.glsl): b and c swapped.
    if (area == 0l || (area > 0l && !both_faces)) {
        return false;
    }
    if (area < 0l) {
        i64vec2 s = t.b;
        t.b = t.c;
        t.c = s;
        vec4 u = t.qb;
        t.qb = t.qc;
        t.qc = u;
    }
    ivec2 lo = ivec2(min(t.a, min(t.b, t.c))), hi = ivec2(max(t.a, max(t.b, t.c)));
    centres_in_box(lo, hi, size, t.first, t.last);
    t.bias = ivec3(fill_bias(ivec2(t.b), ivec2(t.c)), fill_bias(ivec2(t.c), ivec2(t.a)), fill_bias(ivec2(t.a), ivec2(t.b)));
    return all(lessThanEqual(t.first, t.last));
}

// Whether the fan triangle covers `pixel`'s centre; `w`: the edge functions there (the
// weights of the corners opposite them).
bool fan_covers(FanTriangle t, ivec2 pixel, out i64vec3 w) {
    i64vec2 p = i64vec2(pixel * 256 + 128);
    w = i64vec3(edge_function64(t.b, t.c, p), edge_function64(t.c, t.a, p), edge_function64(t.a, t.b, p));
    return all(greaterThanEqual(w - i64vec3(t.bias), i64vec3(0)));
}

// Whether edge s → e (bias: the fill rule's) may cover a sample point (raster_rules.glsl
// RASTER_SAMPLE_LO/HI) of the rectangle [lo, hi]: its edge function is not negative at the
// point where it is largest.
bool edge_reaches(i64vec2 s, i64vec2 e, int bias, ivec2 lo, ivec2 hi) {
    i64vec2 d = e - s;
    ivec2 corner = ivec2(d.y < 0l ? hi.x : lo.x, d.x > 0l ? hi.y : lo.y);
    ivec2 inside = ivec2(d.y < 0l ? RASTER_SAMPLE_HI.x : RASTER_SAMPLE_LO.x, d.x > 0l ? RASTER_SAMPLE_HI.y : RASTER_SAMPLE_LO.y);
    return edge_function64(s, e, i64vec2(corner * 256 + inside)) - int64_t(bias) >= 0l;
}

// Whether any sample point of the rectangle [lo, hi] may be covered (no edge rules it out).
bool fan_reaches(FanTriangle t, ivec2 lo, ivec2 hi) {
    return edge_reaches(t.b, t.c, t.bias.x, lo, hi) && edge_reaches(t.c, t.a, t.bias.y, lo, hi) && edge_reaches(t.a, t.b, t.bias.z, lo, hi);
}

#endif
