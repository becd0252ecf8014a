// The compute shadow raster (--omni-shadow compute; docs/DESIGN.md#compute-shadow-raster):
// every shadowed light's six cube faces drawn by compute shaders into one buffer of 32-bit
// depths, then copied into the cube array the shading passes sample; compiled with
// ORTHO_VIEW, the same shaders draw one orthographic view (the sun's shadow map). What its three shaders
// share: the bindings, the vertex transform and the two ways to rasterise a triangle — by one
// thread (small ones), or by a whole work group over its clipped polygon (large ones, and
// those crossing the near plane). Either way by Vulkan's rules as the graphics modes are
// drawn: the same vertex positions, snapped to 1/256 texel, the top-left rule, both faces
// (a caster need not be closed), the distance to the light over its radius interpolated as
// the fragment shader's input is (perspective-correct; for an orthographic view, the depth
// the rasteriser writes: clip z, w being 1), LESS against what is there: a 32-bit atomic min
// of the depth's bits (non-negative floats order as their bits do). A masked object's
// triangle covers only the texels its alpha mask keeps (raster_surface.glsl), so a leaf's
// shadow has the leaf's shape.
// Needs common.glsl.

#ifndef MANYLIGHTS_OMNI_RASTER_GLSL
#define MANYLIGHTS_OMNI_RASTER_GLSL

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shadows/omni_face.glsl"
#include "visibility/polygon_raster.glsl"

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
// The shadow atlas's tiles of each light (ATLAS only; a stand-in otherwise).
layout(std430, set = 0, binding = 12) readonly buffer ShadowTileBuffer { ShadowCubeTiles cube_tiles[]; };
// The shadowed lights with faces drawn this frame (ATLAS only; a stand-in otherwise): the
// culling and the clear run over these alone, so a frame that keeps every face costs nothing.
layout(std430, set = 0, binding = 13) readonly buffer ShadowRedrawBuffer { uint redrawn_lights[]; };
layout(push_constant) uniform OmniRasterPushBlock { OmniRasterPush omni; };
#define ALPHA_MASK_BINDING 14
#include "common/alpha_mask.glsl"
#include "visibility/raster_surface.glsl"

// One orthographic view instead of cube faces: layer i is light i's view (the sun: one
// light at the origin with radius 1, so positions stay world positions) and omni.projection
// is its view-projection (set by name in shadow_raster.rs).
layout(constant_id = 0) const bool ORTHO_VIEW = false;
// Cube faces into the shadow atlas instead of a cube array: each light's faces are the tiles
// cube_tiles[light] names, of its own size, and only those it redraws are drawn (set by name
// in shadow_raster.rs).
layout(constant_id = 1) const bool ATLAS = false;

#include "visibility/meshlet_geometry.glsl"

// A vertex in the light's frame, in radii (as omni_shadow_vertex.glsl's model_to_light).
vec3 light_relative(uint vertex, mat4 model, vec4 light) {
    uint b = VERTEX_FLOATS * vertex;
    vec3 world = (model * vec4(vertex_data[b], vertex_data[b + 1u], vertex_data[b + 2u], 1.0)).xyz;
    return (world - light.xyz) / light.w;
}

// The light whose view `layer` is.
uint layer_light(uint layer) {
    return ORTHO_VIEW ? layer : layer / 6u;
}

// Vertex `vertex` of an object (`model`) as layer `layer` sees it: its clip position, and
// the attribute whose perspective-correct interpolation gives a texel's depth
// (interpolated_depth) — the position relative to the light, in radii, on a cube face; the
// clip position itself in an orthographic view.
vec3 view_vertex(uint vertex, mat4 model, uint layer, out vec4 clip) {
    vec3 rel = light_relative(vertex, model, shadow_lights[layer_light(layer)]);
    if (ORTHO_VIEW) {
        clip = omni.projection * vec4(rel, 1.0);
        return clip.xyz;
    }
    clip = omni_face_clip(omni.projection, rel, int(layer % 6u));
    return rel;
}

// Texels a side of the view `layer`.
uint view_side(uint layer) {
    return ATLAS ? cube_tiles[layer / 6u].size : opaque_uniform(omni.sizes.x);
}

// The viewport transform of view `layer`, in texels.
vec2 face_xy(vec4 c, uint layer) {
    return viewport_xy(c, vec2(float(view_side(layer))));
}

// Whether the triangle lies wholly beyond one plane of the face's frustum.
bool outside_face(vec4 a, vec4 b, vec4 c) {
    return (a.x > a.w && b.x > b.w && c.x > c.w) || (a.x < -a.w && b.x < -b.w && c.x < -c.w) || (a.y > a.w && b.y > b.w && c.y > c.w)
        || (a.y < -a.w && b.y < -b.w && c.y < -c.w) || (a.z < 0.0 && b.z < 0.0 && c.z < 0.0) || (a.z > a.w && b.z > b.w && c.z > c.w);
}

// The depth at a texel (corners q: xyz as view_vertex gives them, w: 1 / clip w; weights:
// the edge functions opposite each): on a cube face the fragment shader's, the interpolated
// position's distance to the light; in an orthographic view the rasteriser's, clip z.
float interpolated_depth(vec3 weights, vec4 qa, vec4 qb, vec4 qc) {
    vec3 pw = weights * vec3(qa.w, qb.w, qc.w);
    vec3 p = (pw.x * qa.xyz + pw.y * qb.xyz + pw.z * qc.xyz) / (pw.x + pw.y + pw.z);
    return ORTHO_VIEW ? p.z : length(p);
}

// The surface test of triangle `t` (corners `v` in the vertex buffer, clip-space a, b, c in
// its view) of meshlet `m` of object `object`: a masked object's alpha test, else none.
SurfaceTest omni_surface_test(uint object, uvec3 v, vec4 a, vec4 b, vec4 c) {
    SurfaceTest s = no_surface_test();
    if (MASK_TESTS && (instances[object].meshlets.w & INSTANCE_MASKED) != 0u) {
        uvec3 f = VERTEX_FLOATS * v;
        vec4 t[2] = objects[object].uv_transform;
        vec2 ua = transform_uv(t, vec2(vertex_data[f.x + 6u], vertex_data[f.x + 7u]));
        vec2 ub = transform_uv(t, vec2(vertex_data[f.y + 6u], vertex_data[f.y + 7u]));
        vec2 uc = transform_uv(t, vec2(vertex_data[f.z + 6u], vertex_data[f.z + 7u]));
        s = masked_surface(objects[object].alpha, objects[object].alpha_texture, a, b, c, ua, ub, uc);
    }
    return s;
}

// Where `texel` of view `layer` is in the depth buffer.
uint depth_texel(uint layer, ivec2 texel) {
    uint side = omni.sizes.x;
    return ATLAS ? atlas_texel(cube_tiles[layer / 6u].base[layer % 6u], uvec2(texel)) : (layer * side + uint(texel.y)) * side + uint(texel.x);
}

// LESS against what is there (and against the cleared 1.0: beyond the light's reach).
void keep_nearest(uint layer, ivec2 texel, float depth) {
    if (depth < 1.0) {
        atomicMin(cube_depth[depth_texel(layer, texel)], floatBitsToUint(depth));
    }
}

// Whether a covered texel is drawn: every texel of an opaque triangle, a masked one's where
// its alpha mask keeps it.
bool texel_kept(SurfaceTest s, uint layer, ivec2 texel) {
    return surface_kept(s, texel, vec2(float(view_side(layer))));
}

// A triangle beyond the near plane whose box is at most omni.sizes.z texels a side, by this
// thread (corners in texels, q as above); returns the texels covered.
uint raster_small(vec2 pa, vec2 pb, vec2 pc, vec4 qa, vec4 qb, vec4 qc, uint layer, SurfaceTest s) {
    // Both faces are drawn.
    SmallTriangle t;
    if (!small_triangle(pa, pb, pc, ivec2(view_side(layer)), true, t)) {
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
            if (!small_covers(t, ivec2(x, y), w)) {
                continue;
            }
            float depth = interpolated_depth(vec3(w), qa, qb, qc);
            if (texel_kept(s, layer, ivec2(x, y))) {
                covered++;
                keep_nearest(layer, ivec2(x, y), depth);
            }
        }
    }
    return covered;
}

// Draws the fan triangle's texel if covered (and `s` keeps it); returns 1 if it was.
uint fan_texel(FanTriangle t, ivec2 texel, uint layer, SurfaceTest s) {
    i64vec3 w;
    if (!fan_covers(t, texel, w)) {
        return 0u;
    }
    float depth = interpolated_depth(vec3(w), t.qa, t.qb, t.qc);
    if (!texel_kept(s, layer, texel)) {
        return 0u;
    }
    keep_nearest(layer, texel, depth);
    return 1u;
}

// Any triangle by this thread alone, texel by texel over each fan triangle's box (what the
// culling's thread does when the large list is full). Returns the texels covered.
uint raster_large_alone(vec4 ca, vec4 cb, vec4 cc, vec3 ra, vec3 rb, vec3 rc, uint layer, SurfaceTest s) {
    int side = int(view_side(layer));
    Polygon p = clipped_polygon(ca, cb, cc, ra, rb, rc, vec2(float(side)));
    uint covered = 0u;
    for (int k = 1; k + 1 < p.count; k++) {
        FanTriangle t;
        if (!fan_triangle(p.s[0], p.s[k], p.s[k + 1], p.q[0], p.q[k], p.q[k + 1], ivec2(side), true, t)) {
            continue;
        }
        for (int y = t.first.y; y <= t.last.y; y++) {
            for (int x = t.first.x; x <= t.last.x; x++) {
                covered += fan_texel(t, ivec2(x, y), layer, s);
            }
        }
    }
    return covered;
}

// Every triangle of meshlet instance `instance` into view `layer`, by this thread alone (what
// the culling's thread does when the pair list is full: slow, but nothing is lost). Returns
// the texels covered.
uint raster_meshlet_alone(uint instance, uint layer) {
    uvec2 object_meshlet = meshlet_instances[instance];
    Meshlet m = meshlets[object_meshlet.y];
    mat4 model = objects[object_meshlet.x].model;
    uint covered = 0u;
    for (uint t = 0u; t < m.triangles.y; t++) {
        uvec3 v = meshlet_triangle(m, t);
        vec4 a, b, c;
        vec3 ra = view_vertex(v.x, model, layer, a), rb = view_vertex(v.y, model, layer, b), rc = view_vertex(v.z, model, layer, c);
        if (!outside_face(a, b, c)) {
            covered += raster_large_alone(a, b, c, ra, rb, rc, layer, omni_surface_test(object_meshlet.x, v, a, b, c));
        }
    }
    return covered;
}

#endif
