// The compute shadow raster (--omni-shadow compute; docs/DESIGN.md#compute-shadow-raster):
// every shadowed light's six cube faces drawn by compute shaders into one buffer of 32-bit
// depths, then copied into the cube array the shading passes sample. What its three shaders
// share: the bindings, the vertex transform and the two ways to rasterise a triangle — by one
// thread (small ones), or by a whole work group over its clipped polygon (large ones, and
// those crossing the near plane). Either way by Vulkan's rules as the graphics modes are
// drawn: the same vertex positions, snapped to 1/256 texel, the top-left rule, both faces
// (a caster need not be closed), the distance to the light over its radius interpolated as
// the fragment shader's input is (perspective-correct), LESS against what is there: a
// 32-bit atomic min of the depth's bits (non-negative floats order as their bits do).
// Needs common.glsl.

#ifndef MANYLIGHTS_OMNI_RASTER_GLSL
#define MANYLIGHTS_OMNI_RASTER_GLSL

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "omni_face.glsl"
#include "raster_rules.glsl"

// xyz: where each shadowed light is this frame; w: its radius (cube i: light i).
layout(std430, set = 0, binding = 0) readonly buffer ShadowLightBuffer { vec4 shadow_lights[]; };
layout(std430, set = 0, binding = 1) readonly buffer ObjectBuffer { ObjectData objects[]; };
layout(std430, set = 0, binding = 2) readonly buffer InstanceBuffer { Instance instances[]; };
layout(std430, set = 0, binding = 3) readonly buffer MeshletBuffer { Meshlet meshlets[]; };
// Per meshlet instance: (object, meshlet).
layout(std430, set = 0, binding = 4) readonly buffer MeshletInstanceBuffer { uvec2 meshlet_instances[]; };
layout(std430, set = 0, binding = 5) readonly buffer MeshletVertexBuffer { uint meshlet_vertices[]; };
layout(std430, set = 0, binding = 6) readonly buffer MeshletTriangleBuffer { uint meshlet_triangles[]; };
layout(std430, set = 0, binding = 7) readonly buffer VertexBuffer { float vertex_data[]; };
layout(std430, set = 0, binding = 8) buffer OmniRasterCounterBuffer { OmniRasterCounters counters; };
// What the culling kept: (meshlet instance, cube layer = light · 6 + face).
layout(std430, set = 0, binding = 9) buffer OmniPairBuffer { uvec2 pairs[]; };
// The large triangles: (pair, triangle of its meshlet).
layout(std430, set = 0, binding = 10) buffer OmniLargeBuffer { uvec2 large_triangles[]; };
// Per cube layer, row by row: the nearest depth's bits; 1.0 where nothing is in reach.
layout(std430, set = 0, binding = 11) buffer CubeDepthBuffer { uint cube_depth[]; };
layout(push_constant) uniform OmniRasterPushBlock { OmniRasterPush omni; };

#include "meshlet_geometry.glsl"

// The larger work groups loop over their lists: a dispatch has at most this many.
const uint MAX_GROUPS = 65535u;

// Where clipping against the sides begins: |x|, |y| ≤ GUARD · w, a band 1.5 faces wide around
// the face that keeps every snapped coordinate (and the edge functions' products) in range.
const float GUARD = 4.0;

// A vertex in the light's frame, in radii (as omni_shadow_vertex.glsl's model_to_light).
vec3 light_relative(uint vertex, mat4 model, vec4 light) {
    uint b = VERTEX_FLOATS * vertex;
    vec3 world = (model * vec4(vertex_data[b], vertex_data[b + 1u], vertex_data[b + 2u], 1.0)).xyz;
    return (world - light.xyz) / light.w;
}

// The viewport transform of a face, in texels.
vec2 face_xy(vec4 c) {
    float half_size = float(omni.sizes.x) * 0.5;
    return c.xy / c.w * half_size + half_size;
}

// Whether the triangle lies wholly beyond one plane of the face's frustum.
bool outside_face(vec4 a, vec4 b, vec4 c) {
    return (a.x > a.w && b.x > b.w && c.x > c.w) || (a.x < -a.w && b.x < -b.w && c.x < -c.w) || (a.y > a.w && b.y > b.w && c.y > c.w)
        || (a.y < -a.w && b.y < -b.w && c.y < -c.w) || (a.z < 0.0 && b.z < 0.0 && c.z < 0.0) || (a.z > a.w && b.z > b.w && c.z > c.w);
}

// The fragment shader's depth at a texel: the interpolated position's distance to the light
// (corners q: xyz in radii, w: 1 / clip w; weights: the edge functions opposite each).
float interpolated_distance(vec3 weights, vec4 qa, vec4 qb, vec4 qc) {
    vec3 pw = weights * vec3(qa.w, qb.w, qc.w);
    return length((pw.x * qa.xyz + pw.y * qb.xyz + pw.z * qc.xyz) / (pw.x + pw.y + pw.z));
}

// LESS against what is there (and against the cleared 1.0: beyond the light's reach).
void keep_nearest(uint layer, ivec2 texel, float depth) {
    if (depth < 1.0) {
        uint side = omni.sizes.x;
        atomicMin(cube_depth[(layer * side + uint(texel.y)) * side + uint(texel.x)], floatBitsToUint(depth));
    }
}

// A triangle beyond the near plane whose box is at most omni.sizes.z texels a side, by this
// thread (corners in texels, q as above); returns the texels covered.
uint raster_small(vec2 pa, vec2 pb, vec2 pc, vec4 qa, vec4 qb, vec4 qc, uint layer) {
    // Both faces are drawn.
    SmallTriangle t;
    if (!small_triangle(pa, pb, pc, ivec2(omni.sizes.x), true, t)) {
        return 0u;
    }
    if (t.swapped) {
        vec4 u = qb;
        qb = qc;
        qc = u;
    }
    uint covered = 0u;
    for (int y = t.first.y; y <= t.last.y; y++) {
        for (int x = t.first.x; x <= t.last.x; x++) {
            ivec3 w;
            if (small_covers(t, ivec2(x, y), w)) {
                covered++;
                keep_nearest(layer, ivec2(x, y), interpolated_distance(vec3(w), qa, qb, qc));
            }
        }
    }
    return covered;
}

int64_t edge_function64(i64vec2 s, i64vec2 e, i64vec2 p) {
    i64vec2 d = e - s;
    return d.x * (p.y - s.y) - d.y * (p.x - s.x);
}

const int MAX_POLYGON = 8; // a triangle clipped by five planes

// Clip the triangle (clip-space corners, their q as above) against the near plane and the
// guard band; `count` corners of the convex polygon left. A new corner on an edge is found
// from the edge's inside end, whichever way the edge is walked: two triangles sharing that
// edge get the same corner, so they stay watertight.
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
                // Position, not 1/w: interpolated linearly in clip space, then inverted below.
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

// A large triangle's clipped polygon: its corners snapped to the sub-pixel grid, their q (as
// above), drawn as the fan (0, k, k + 1).
struct Polygon {
    int count;
    i64vec2 s[MAX_POLYGON];
    vec4 q[MAX_POLYGON];
};

Polygon clipped_polygon(vec4 ca, vec4 cb, vec4 cc, vec3 ra, vec3 rb, vec3 rc) {
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
        p.s[i] = i64vec2(ivec2(roundEven(face_xy(clip[i]) * SUBPIXEL)));
        p.q[i].w = 1.0 / clip[i].w;
    }
    return p;
}

// One triangle of a polygon's fan, set up for its texels: corners ordered so the interior is
// on every edge's positive side, the fill rule's biases, the texel centres in its box.
struct FanTriangle {
    i64vec2 a, b, c;
    vec4 qa, qb, qc;
    ivec3 bias;
    ivec2 first, last;
};

// The fan triangle with corners (a, b, c), their q; false if it covers no texel centre of
// the face (zero area, or its box misses the face).
bool fan_triangle(i64vec2 a, i64vec2 b, i64vec2 c, vec4 qa, vec4 qb, vec4 qc, out FanTriangle t) {
    t.a = a;
    t.b = b;
    t.c = c;
    t.qa = qa;
    t.qb = qb;
    t.qc = qc;
    int64_t area = (t.b.x - t.a.x) * (t.c.y - t.a.y) - (t.b.y - t.a.y) * (t.c.x - t.a.x);
    if (area == 0l) {
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
    int side = int(omni.sizes.x);
    t.first = max((lo - 128 + 255) >> 8, ivec2(0));
    t.last = min((hi - 128) >> 8, ivec2(side - 1));
    t.bias = ivec3(fill_bias(ivec2(t.b), ivec2(t.c)), fill_bias(ivec2(t.c), ivec2(t.a)), fill_bias(ivec2(t.a), ivec2(t.b)));
    return all(lessThanEqual(t.first, t.last));
}

// The three edge functions at a texel's centre (the weights of the corners opposite them).
i64vec3 fan_edges(FanTriangle t, ivec2 texel) {
    i64vec2 p = i64vec2(texel * 256 + 128);
    return i64vec3(edge_function64(t.b, t.c, p), edge_function64(t.c, t.a, p), edge_function64(t.a, t.b, p));
}

// Draws the fan triangle's texel if covered; returns 1 if it was.
uint fan_texel(FanTriangle t, ivec2 texel, uint layer) {
    i64vec3 w = fan_edges(t, texel);
    if (any(lessThan(w - i64vec3(t.bias), i64vec3(0)))) {
        return 0u;
    }
    keep_nearest(layer, texel, interpolated_distance(vec3(w), t.qa, t.qb, t.qc));
    return 1u;
}

// Whether any texel centre of the rectangle [lo, hi] may be covered: no edge function is
// negative at the rectangle's corner where it is largest.
bool fan_reaches(FanTriangle t, ivec2 lo, ivec2 hi) {
    i64vec2 s[3] = i64vec2[3](t.b, t.c, t.a);
    i64vec2 e[3] = i64vec2[3](t.c, t.a, t.b);
    for (int i = 0; i < 3; i++) {
        i64vec2 d = e[i] - s[i];
        ivec2 corner = ivec2(d.y < 0l ? hi.x : lo.x, d.x > 0l ? hi.y : lo.y);
        if (edge_function64(s[i], e[i], i64vec2(corner * 256 + 128)) - int64_t(t.bias[i]) < 0l) {
            return false;
        }
    }
    return true;
}

// Any triangle by this thread alone, texel by texel over each fan triangle's box (what the
// culling's thread does when the large list is full). Returns the texels covered.
uint raster_large_alone(vec4 ca, vec4 cb, vec4 cc, vec3 ra, vec3 rb, vec3 rc, uint layer) {
    Polygon p = clipped_polygon(ca, cb, cc, ra, rb, rc);
    uint covered = 0u;
    for (int k = 1; k + 1 < p.count; k++) {
        FanTriangle t;
        if (!fan_triangle(p.s[0], p.s[k], p.s[k + 1], p.q[0], p.q[k], p.q[k + 1], t)) {
            continue;
        }
        for (int y = t.first.y; y <= t.last.y; y++) {
            for (int x = t.first.x; x <= t.last.x; x++) {
                covered += fan_texel(t, ivec2(x, y), layer);
            }
        }
    }
    return covered;
}

#endif
