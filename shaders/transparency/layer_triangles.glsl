// What the transparent layers' compute builds share (transparent_build_compute.glsl over
// tiles, transparent_build_triangles.glsl a thread per triangle): the bindings, a triangle's
// set-up in shared memory (one of CHUNK places), its coverage test and its surface. Both
// builds run these same functions, so a triangle leaves the same fragments, bit for bit,
// whichever builds it.
//
// Triangles are rasterised in homogeneous coordinates (no clipping: a triangle crossing the
// eye plane still covers exactly its visible part): with M = (x, y, w) of the three vertices as
// columns, the rows of adj(M) are edge functions whose values at the pixel's (x, y, 1),
// normalised, are its perspective-correct barycentrics; the pixel is inside where all three
// have the sign of det(M). A pixel on an edge shared by two triangles belongs to one of them
// (the two edge functions are exact negatives of each other; the sign of their x, then y,
// coefficient decides). Depth and attributes are interpolated with those barycentrics; the
// texture gradients are their differences one pixel to the right and one down.
//
// The includer defines OPAQUE_DEPTH_BUFFER for the compute raster's 64-bit buffer, and sets
// its work group size.

#ifndef MANYLIGHTS_LAYER_TRIANGLES_GLSL
#define MANYLIGHTS_LAYER_TRIANGLES_GLSL
#extension GL_KHR_shader_subgroup_arithmetic : require

#define SURFACE_GRADIENTS 1
#include "common/common.glsl"

#include "common/scene_bindings.glsl"
#include "common/textures.glsl"
#include "common/surface.glsl"
#define ALPHA_MASK_BINDING 11
#include "common/alpha_mask.glsl"
#include "common/blended_cores.glsl"
#define LAYER_BINDING 14
#include "transparency/layers.glsl"
#include "common/opaque_depth.glsl"
#ifdef OPAQUE_DEPTH_BUFFER
// The visibility raster's depth pyramid, made after its early phase: no nearer than the
// opaque depth the build tests against (the late phase only brings surfaces nearer).
layout(std430, set = 0, binding = 17) readonly buffer DepthPyramidBuffer { float depth_pyramid[]; };
#include "visibility/depth_pyramid_test.glsl"
#endif

// The transparent objects' meshes one after another (gpu_mesh.rs: 12 floats a vertex, position, normal, uv,
// tangent; three indices a triangle, each from its mesh's first vertex), and this frame's
// objects, those of one texture set side by side.
layout(std430, set = 3, binding = 0) readonly buffer MeshVertexBuffer { float mesh_vertices[]; };
layout(std430, set = 3, binding = 1) readonly buffer MeshIndexBuffer { uint mesh_indices[]; };
layout(std430, set = 3, binding = 2) buffer LayerObjectBuffer { LayerObject layer_objects[]; };
// Per texture set (by its slot), LIST_WORDS words on the triangles the per-triangle build
// leaves to others: how many it listed for a work group each (transparent_build_large.glsl)
// as single-triangle entries from large_list.x on, and how many huge ones for the tiles'
// build from the end of that room (large_list.x + large_list.y) down — the room holds all of
// them, one entry at most a triangle — and the two builds' work groups, which they are
// dispatched with (VkDispatchIndirectCommand: 1, 1 and 0, tile rows, 1 before the build).
layout(std430, set = 3, binding = 3) buffer LargeTriangleCountBuffer { uint large_triangles[]; };
const uint LIST_WORDS = 12u;
const uint LIST_LARGE = 0u;           // triangles listed for a work group each
const uint LIST_HUGE = 1u;            // triangles listed for the tiles
const uint LIST_LARGE_GROUPS = 4u;    // x, y, z: the large triangles' work groups
const uint LIST_HUGE_GROUPS = 8u;     // x, y, z: the tiles' (x: the image's tile columns once one is listed)
// dispatch_objects: x: the dispatch's first entry in layer_objects, y: its entries; z: tiles:
// the first pixel of the rectangle it covers (y << 16 | x, each a multiple of the tile's
// size), per triangle: its entries' triangles; w: 0 for the CPU's entries, else 1 + the
// texture set's slot in large_triangles (per triangle: where it lists; the others: whose
// list they draw, its count and place replacing x and y). large_list: x: the first entry of
// the texture set's room for listed triangles, y: its size; z: per triangle: the first
// triangle of this dispatch's piece; w: per triangle: 1 where the piece's triangles are
// cores, which the compute raster lists as candidates (built here only where it left them
// to this build: CullCounters.candidates.y). The candidates' build: dispatch_objects.x: the
// texture set it builds.
layout(push_constant) uniform LayerDispatchBlock {
    uvec4 dispatch_objects;
    uvec4 large_list;
};

#ifdef OPAQUE_DEPTH_BUFFER
// The culling's counters: CullCounters.candidates, whether the compute raster listed the
// candidates of transparent objects' cores (transparent_build_candidates.glsl) or left the
// cores to the per-triangle build, and how many.
layout(std430, set = 3, binding = 9) readonly buffer CullCounterBuffer { CullCounters counters; };
#endif
#ifdef LAYER_CANDIDATE_BUILD
// The candidates' build: the scene's meshlets, to set up the triangle a visibility id names;
// the raster's candidates; the objects' instances (Instance.surface: their textures and
// texture set).
layout(std430, set = 3, binding = 4) readonly buffer MeshletBuffer { Meshlet meshlets[]; };
layout(std430, set = 3, binding = 5) readonly buffer MeshletVertexBuffer { uint meshlet_vertices[]; };
layout(std430, set = 3, binding = 6) readonly buffer MeshletTriangleBuffer { uint meshlet_triangles[]; };
layout(std430, set = 3, binding = 7) readonly buffer VertexBuffer { float vertex_data[]; };
layout(std430, set = 3, binding = 8) readonly buffer MeshletInstanceBuffer { uvec2 meshlet_instances[]; };
layout(std430, set = 3, binding = 10) readonly buffer LayerCandidateBuffer { uvec4 layer_candidates[]; };
layout(std430, set = 3, binding = 11) readonly buffer InstanceBuffer { Instance instances[]; };
#include "visibility/meshlet_geometry.glsl"
#endif

// The side of the tiles' build's square tiles, in pixels.
const uint LAYER_TILE = 16u;
// The largest box, in pixels a side, a work group of the large triangles' build walks
// (transparent_build_large.glsl, 16×16 threads a block), and the words of a thread's bits,
// one a block.
const int GROUP_BOX = 256;
const uint GROUP_BLOCK_WORDS = uint((GROUP_BOX / 16) * (GROUP_BOX / 16)) / 32u;

// Triangles set up at once (the tiles' build: 64; the per-triangle build: a place a thread;
// a work group's own triangle: 1).
#ifndef LAYER_SLOTS
#define LAYER_SLOTS 64u
#endif
const uint CHUNK = LAYER_SLOTS;
// CHUNK triangles, set up: edge functions (rows of adj(M), times the sign of det(M)),
// clip z and w per vertex, world-space normals and tangents (w: handedness), texture
// coordinates; (object, TRIANGLE_* bits, its textures), its alpha factor, alpha texture
// (ObjectData.alpha_texture) and material.
shared vec3 tri_edges[CHUNK][3];
shared vec3 tri_z[CHUNK];
shared vec3 tri_w[CHUNK];
shared vec3 tri_normal[CHUNK][3];
shared vec4 tri_tangent[CHUNK][3];
shared vec2 tri_uv[CHUNK][3];
shared uvec3 tri_object[CHUNK];
shared float tri_alpha[CHUNK];
shared uvec4 tri_alpha_texture[CHUNK];
shared vec4 tri_material[CHUNK];

const uint TRIANGLE_DRAWN = 1u; // faces a way its object is drawn from (and is not degenerate)
const uint TRIANGLE_FRONT = 2u; // faces the viewer

struct Vtx {
    vec3 position;
    vec3 normal;
    vec2 uv;
    vec4 tangent;
};

// A function `name` reading vertex i of the float array `data` (VERTEX_FLOATS a vertex, as
// gpu_mesh.rs lays them out): the transparent meshes' and the meshlets' alike.
#define VERTEX_READER(name, data)                                                                            \
    Vtx name(uint i) {                                                                                       \
        uint b = VERTEX_FLOATS * i;                                                                          \
        Vtx v;                                                                                               \
        v.position = vec3(data[b], data[b + 1u], data[b + 2u]);                                              \
        v.normal = vec3(data[b + 3u], data[b + 4u], data[b + 5u]);                                           \
        v.uv = vec2(data[b + 6u], data[b + 7u]);                                                             \
        v.tangent = vec4(data[b + 8u], data[b + 9u], data[b + 10u], data[b + 11u]);                          \
        return v;                                                                                            \
    }
VERTEX_READER(mesh_vertex, mesh_vertices)

// Set up in place `slot` the triangle of `corners` of object `object.x` (its own textures:
// `object.y`); `box` gets the pixels whose centres it may cover (first, last; inclusive,
// within the image: empty where none).
void set_up_corners(uint slot, uvec2 object, Vtx corners[3], out ivec4 box) {
    uint o = object.x;
    mat4 model = objects[o].model;
    mat3 normal_matrix = mat3(objects[o].normal_matrix);
    vec4 uv_transform[2] = objects[o].uv_transform;
    mat4 view_proj = frame.proj * frame.view;
    vec4 clip[3];
    for (uint v = 0u; v < 3u; v++) {
        Vtx x = corners[v];
        vec3 world = (model * vec4(x.position, 1.0)).xyz;
        clip[v] = view_proj * vec4(world, 1.0);
        tri_normal[slot][v] = normal_matrix * x.normal;
        tri_uv[slot][v] = transform_uv(uv_transform, x.uv);
        tri_tangent[slot][v] = vec4(mat3(model) * x.tangent.xyz, x.tangent.w);
    }
    vec3 a = clip[0].xyw, b = clip[1].xyw, c = clip[2].xyw;
    vec3 r0 = cross(b, c), r1 = cross(c, a), r2 = cross(a, b);
    float det = dot(a, r0);
    // Front faces wind counter-clockwise as the pipelines see them (Y-flipped projection):
    // det < 0 here.
    bool front = det < 0.0;
    uvec4 alpha_texture = objects[o].alpha_texture;
    bool drawn = det != 0.0 && (front || (alpha_texture.x & OBJECT_DOUBLE_SIDED) != 0u);
    float s = sign(det);
    tri_edges[slot][0] = r0 * s;
    tri_edges[slot][1] = r1 * s;
    tri_edges[slot][2] = r2 * s;
    tri_z[slot] = vec3(clip[0].z, clip[1].z, clip[2].z);
    tri_w[slot] = vec3(clip[0].w, clip[1].w, clip[2].w);
    tri_object[slot] = uvec3(o, (drawn ? TRIANGLE_DRAWN : 0u) | (front ? TRIANGLE_FRONT : 0u), object.y);
    tri_alpha[slot] = objects[o].alpha.y;
    tri_alpha_texture[slot] = alpha_texture;
    tri_material[slot] = objects[o].material;
    // The corners on the near plane's far side (clip z ≥ 0, where depth is; w is positive
    // there) and where the edges cross it, projected: a triangle reaching behind the eye
    // gets the box of the part that may be seen.
    vec2 size = vec2(frame.viewport.xy);
    vec2 lo = vec2(1e30), hi = vec2(-1e30);
    for (uint v = 0u; v < 3u; v++) {
        vec4 x = clip[v], y = clip[(v + 1u) % 3u];
        if (x.z >= 0.0 && x.w > 0.0) {
            vec2 p = (x.xy / x.w + 1.0) * 0.5 * size;
            lo = min(lo, p);
            hi = max(hi, p);
        }
        if ((x.z >= 0.0) != (y.z >= 0.0)) {
            vec4 c = mix(x, y, x.z / (x.z - y.z));
            if (c.w > 0.0) {
                vec2 p = (c.xy / c.w + 1.0) * 0.5 * size;
                lo = min(lo, p);
                hi = max(hi, p);
            }
        }
    }
    // The pixels whose centre p + 0.5 lies within [lo, hi] — with anti-aliasing, some
    // sample of theirs: within half a pixel of the centre — widened by an eighth of a pixel for
    // the projection's rounding (float rounding at coordinates up to 16,384 pixels is under a
    // five-hundredth of one; a corner far outside, where it grows, lies beyond the clamp).
    // Clamped before the conversion (a crossing's projection may be far outside). A box a
    // pixel wider each way than this walked four times the pixels of a small triangle's.
    float margin = 0.125;
    if (VISIBILITY_SAMPLES != 1u) {
        margin += 0.5;
    }
    lo = clamp(ceil(lo - 0.5 - margin), vec2(0.0), size);
    hi = clamp(floor(hi - 0.5 + margin), vec2(-1.0), size - 1.0);
    box = ivec4(ivec2(lo), ivec2(hi));
#ifdef OPAQUE_DEPTH_BUFFER
    // A triangle wholly in front of the eye whose nearest corner lies behind the farthest
    // opaque depth over its box leaves no fragment: its box is emptied, and no build walks
    // it (a dense crown's cores hide most of its leaves). Its fragments' depths lie between
    // its corners' up to their rounding, which the margin of 2^-20 covers.
    if (all(greaterThanEqual(vec3(clip[0].z, clip[1].z, clip[2].z), vec3(0.0))) && all(greaterThan(tri_w[slot], vec3(0.0)))
        && all(lessThanEqual(box.xy, box.zw))) {
        float nearest = min(clip[0].z / clip[0].w, min(clip[1].z / clip[1].w, clip[2].z / clip[2].w));
        uvec2 image = frame.viewport.xy;
        if (nearest - 1.0 / 1048576.0 > pyramid_farthest(image, pyramid_levels(image), box.xy, box.zw)) {
            box = ivec4(0, 0, -1, -1);
        }
    }
#endif
}

// Set up triangle `k` of entry `entry` (of layer_objects) in place `slot`, as set_up_corners
// says.
void set_up_triangle(uint slot, LayerObject entry, uint k, out ivec4 box) {
    uint first = entry.ids.z + 3u * k;
    Vtx corners[3];
    for (uint v = 0u; v < 3u; v++) {
        corners[v] = mesh_vertex(entry.place.x + mesh_indices[first + v]);
    }
    set_up_corners(slot, entry.ids.xy, corners, box);
}

// Whether the points where an edge function (coefficients `c`) is 0 belong to this triangle:
// the sign of its x, then y, coefficient decides.
bool edge_owns_ties(vec2 c) {
    return c.x > 0.0 || (c.x == 0.0 && c.y > 0.0);
}

// Whether a pixel where edge function `e` (coefficients `c`) is 0 belongs to this triangle.
bool edge_owns(float e, vec2 c) {
    return e > 0.0 || (e == 0.0 && edge_owns_ties(c));
}

// Triangle `i`'s three edge functions at the point `q` (x, y in NDC, 1).
vec3 edge_values(uint i, vec3 q) {
    return vec3(dot(tri_edges[i][0], q), dot(tri_edges[i][1], q), dot(tri_edges[i][2], q));
}

// The barycentrics of point `q` (x, y in NDC, 1) on triangle `i`'s plane.
vec3 barycentrics(uint i, vec3 q) {
    vec3 e = edge_values(i, q);
    return e / (e.x + e.y + e.z);
}

// Whether triangle `i` covers the point `q` (x, y in NDC, 1) at a depth in [0, 1]: its
// barycentrics and depth there.
bool layer_point(uint i, vec3 q, out vec3 w, out float depth) {
    w = vec3(0.0);
    depth = 0.0;
    vec3 e = edge_values(i, q);
    if (!(edge_owns(e.x, tri_edges[i][0].xy) && edge_owns(e.y, tri_edges[i][1].xy) && edge_owns(e.z, tri_edges[i][2].xy))) {
        return false;
    }
    float sum = e.x + e.y + e.z;
    if (sum <= 0.0) {
        return false;
    }
    w = e / sum;
    depth = dot(w, tri_z[i]) / dot(w, tri_w[i]);
    return depth >= 0.0 && depth <= 1.0;
}


// How far in front of the opaque depth a layer of triangle `i` at the point `q` (x, y in
// NDC, 1) must lie not to be taken as lying on it (blended_cores.glsl): the visibility raster
// drew a core's point at the depth its snapped corners give (moved by at most 1/512 pixel
// each way), and in floats. So the slack is the triangle's depth change over 1/128 pixel
// (four times the snapping's reach) plus 2^-20 (16 steps of a float near 1): a surface
// seen at a grazing angle gets more, one seen head-on almost none — a soft-edged decal 2 mm
// in front of a wall 3 m away keeps its edges. Too little slack only costs a layer of alpha
// 1 blending the core's own colour over it; a fragment within it of a surface other than
// its core is taken as lying on that surface. (Once a triangle at its set-up instead of
// once a pixel, the H200's forest build took 1.36 ms against 1.04, 3.93 against 3.04 at 8
// samples.)
float core_slack(uint i, vec3 q, vec2 to_ndc) {
    vec3 e = edge_values(i, q);
    vec3 ex = vec3(tri_edges[i][0].x, tri_edges[i][1].x, tri_edges[i][2].x);
    vec3 ey = vec3(tri_edges[i][0].y, tri_edges[i][1].y, tri_edges[i][2].y);
    float a = dot(e, tri_z[i]), b = dot(e, tri_w[i]);
    float slack = 1.0 / 1048576.0;
    if (b > 0.0) {
        // depth = a / b; its derivatives along x and y in NDC, then per pixel.
        float dx = (dot(ex, tri_z[i]) * b - a * dot(ex, tri_w[i])) / (b * b);
        float dy = (dot(ey, tri_z[i]) * b - a * dot(ey, tri_w[i])) / (b * b);
        slack += (abs(dx) * to_ndc.x + abs(dy) * to_ndc.y) * (1.0 / 128.0);
    }
    return slack;
}

// Which samples of pixel `p` (centre `q`, x and y in NDC) triangle `i` covers in front of the
// opaque samples there (a bit each): layer_point's test, the triangle read from shared memory
// once for all of them, each edge's tie rule decided once, and the depth a/b of the edge
// functions' weights compared as a against b (b > 0: in front of the eye) — the anti-aliased
// build runs it for every pixel its triangles' boxes hold. Unrolled (the per-sample values
// stay in registers): on the H200 the BLEND forest's build at 8 samples took 2.60 ms, 2.70
// as a loop (before core_slack). Splitting it, to read the opaque samples only where a
// sample lies in front of the depth pyramid's farthest over the pixel, made it 3.59.
uint samples_in_front(uint i, ivec2 p, vec2 to_ndc) {
    vec3 r0 = tri_edges[i][0], r1 = tri_edges[i][1], r2 = tri_edges[i][2];
    vec3 z = tri_z[i], w = tri_w[i];
    // edge_owns' rule where an edge function is 0, per edge.
    bvec3 ties = bvec3(edge_owns_ties(r0.xy), edge_owns_ties(r1.xy), edge_owns_ties(r2.xy));
    bool core = BLENDED_CORES && (tri_alpha_texture[i].x & OBJECT_CORE) != 0u;
    // A core's samples on the opaque surface are left out whatever the pixel's alpha (which
    // the layer takes at the pixel, the raster per sample): where the raster found alpha 1
    // they are opaque, the layer holds the others.
    float slack = core ? core_slack(i, vec3((vec2(p) + 0.5) * to_ndc - 1.0, 1.0), to_ndc) : 0.0;
    uint covered = 0u;
    [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
        vec3 q = vec3(sample_xy(p, k) * to_ndc - 1.0, 1.0);
        vec3 e = vec3(dot(r0, q), dot(r1, q), dot(r2, q));
        bvec3 pos = greaterThan(e, vec3(0.0)), zero = equal(e, vec3(0.0));
        bool inside = (pos.x || (zero.x && ties.x)) && (pos.y || (zero.y && ties.y)) && (pos.z || (zero.z && ties.z));
        float a = dot(e, z), b = dot(e, w);
        float opaque = opaque_depth_of_sample(p, k) - slack;
        if (inside && b > 0.0 && a >= 0.0 && a <= b && a < opaque * b) {
            covered |= 1u << k;
        }
    }
    return covered;
}

// How much the edge function of coefficients `r` may change from a pixel's centre to any of
// its samples: over half a pixel each way, with a margin for rounding.
float edge_reach(vec3 r, vec2 to_ndc) {
    return 1.01 * (0.5 * (abs(r.x) * to_ndc.x + abs(r.y) * to_ndc.y));
}

// Whether no sample of the pixel centred at `q` can lie inside triangle `i`: an edge function
// below zero by more than its reach (this only skips work, layer_point decides).
bool samples_outside(uint i, vec3 q, vec2 to_ndc) {
    for (uint j = 0u; j < 3u; j++) {
        vec3 r = tri_edges[i][j];
        if (dot(r, q) + edge_reach(r, to_ndc) < 0.0) {
            return true;
        }
    }
    return false;
}

// Whether triangle `i` leaves a fragment at pixel `p`: the samples it covers in front of the
// opaque surface there (`covered`, a bit each; without anti-aliasing, bit 0: the centre, in
// front of `opaque`), and at the point the pixel shades it (`q`: the centre, or with
// anti-aliasing visibility_samples.glsl shading_xy of its samples — inside the triangle, as
// they are) its barycentrics, depth and coverage. `listed`: 0, or the samples the compute
// raster found it covers there in front of the opaque ones, which it takes as they are.
bool layer_fragment_of(uint i, ivec2 p, vec2 to_ndc, float opaque, uint listed, out vec3 q, out uint covered, out vec3 w, out float depth,
                       out float alpha) {
    q = vec3((vec2(p) + 0.5) * to_ndc - 1.0, 1.0);
    covered = 0u;
    w = vec3(0.0);
    depth = 0.0;
    alpha = 0.0;
    if ((tri_object[i].y & TRIANGLE_DRAWN) == 0u) {
        return false;
    }
    if (listed != 0u) {
        covered = listed;
        q = vec3(shading_xy(p, covered) * to_ndc - 1.0, 1.0);
        w = barycentrics(i, q);
        depth = dot(w, tri_z[i]) / dot(w, tri_w[i]);
    } else if (VISIBILITY_SAMPLES == 1u) {
        if (!layer_point(i, q, w, depth) || depth >= opaque) {
            return false;
        }
        covered = 1u;
    } else {
        if (samples_outside(i, q, to_ndc)) {
            return false;
        }
        covered = samples_in_front(i, p, to_ndc);
        if (covered == 0u) {
            return false;
        }
        q = vec3(shading_xy(p, covered) * to_ndc - 1.0, 1.0);
        w = barycentrics(i, q);
        depth = dot(w, tri_z[i]) / dot(w, tri_w[i]);
    }
    alpha = tri_alpha[i];
    if ((tri_alpha_texture[i].x & OBJECT_ALPHA_TEXTURE) != 0u) {
        alpha *= texture_alpha(tri_alpha_texture[i], w.x * tri_uv[i][0] + w.y * tri_uv[i][1] + w.z * tri_uv[i][2]);
    }
    // (Nested: the build's reflection evaluates no `&&` of two constants.)
    if (BLENDED_CORES) {
        if (VISIBILITY_SAMPLES == 1u && listed == 0u && alpha >= 1.0 && (tri_alpha_texture[i].x & OBJECT_CORE) != 0u
            && depth >= opaque - core_slack(i, q, to_ndc)) {
            return false;
        }
    }
    return alpha > 0.0;
}

// layer_fragment_of for the builds that test their triangles' coverage themselves.
bool layer_fragment(uint i, ivec2 p, vec2 to_ndc, float opaque, out vec3 q, out uint covered, out vec3 w, out float depth, out float alpha) {
    return layer_fragment_of(i, p, to_ndc, opaque, 0u, q, covered, w, depth, alpha);
}

// The surface of triangle `i` at barycentrics `w` (pixel `q`), packed for its node.
LayerSurface layer_surface(uint i, vec3 q, vec3 w, float alpha, vec2 to_ndc) {
    vec2 uv = w.x * tri_uv[i][0] + w.y * tri_uv[i][1] + w.z * tri_uv[i][2];
    // The texture coordinates one pixel to the right and one down.
    vec3 wx = barycentrics(i, q + vec3(to_ndc.x, 0.0, 0.0)), wy = barycentrics(i, q + vec3(0.0, to_ndc.y, 0.0));
    surface_uv_dx = wx.x * tri_uv[i][0] + wx.y * tri_uv[i][1] + wx.z * tri_uv[i][2] - uv;
    surface_uv_dy = wy.x * tri_uv[i][0] + wy.y * tri_uv[i][1] + wy.z * tri_uv[i][2] - uv;
    vec3 n = w.x * tri_normal[i][0] + w.y * tri_normal[i][1] + w.z * tri_normal[i][2];
    vec4 tangent = w.x * tri_tangent[i][0] + w.y * tri_tangent[i][1] + w.z * tri_tangent[i][2];
    bool front = (tri_object[i].y & TRIANGLE_FRONT) != 0u;
    Surface sf = surface_at(front ? n : -n, tangent, uv, tri_object[i].z, tri_material[i], tri_object[i].x);
    uvec4 surface = pack_layer_surface(sf.normal, vec4(sf.albedo_factor, sf.occlusion), sf.roughness_metallic, min(alpha, 1.0),
                                       vec4(sf.emissive_factor, sf.normal_spread));
    return LayerSurface(surface, LOBE_TEXTURES ? pack_lobe_texels(sf.lobes) : uvec4(0u));
}

// Whether triangle `slot` leaves a fragment at pixel `p` in front of the opaque depth (the
// opaque depth read only where it may cover the pixel: most of a box lies outside it;
// layer_fragment decides exactly).
bool pixel_fragment(uint slot, ivec2 p, vec2 to_ndc) {
    vec3 q = vec3((vec2(p) + 0.5) * to_ndc - 1.0, 1.0), w;
    float depth, alpha;
    uint covered;
    vec3 e = edge_values(slot, q);
    // With anti-aliasing a triangle may cover samples and not the centre.
    bool may = VISIBILITY_SAMPLES != 1u || all(greaterThanEqual(e, vec3(0.0)));
    return may && layer_fragment(slot, p, to_ndc, opaque_depth_at(p), q, covered, w, depth, alpha);
}

// Keep pixel `p`'s fragment of triangle `slot`, which pixel_fragment (or with `listed`,
// layer_fragment_of) found, in node `node` (dropped where the pool is full), linked in front
// of its pixel's list by an atomic exchange of the head. Its barycentrics, depth and
// coverage found again (not kept from the test: registers), its existence not: the writes
// follow the test's bits, so they take exactly the room counted.
void keep_fragment_of(uint slot, ivec2 p, uint node, uint capacity, vec2 to_ndc, uint listed) {
    vec3 q, w;
    float depth, alpha;
    uint covered;
    layer_fragment_of(slot, p, to_ndc, opaque_depth_at(p), listed, q, covered, w, depth, alpha);
    if (node < capacity) {
        uint next = atomicExchange(layer_heads[layer_pixel(p)], node);
        write_layer(node, p, depth, next, tri_object[slot].x, covered, layer_surface(slot, q, w, alpha, to_ndc));
    }
}

void keep_fragment(uint slot, ivec2 p, uint node, uint capacity, vec2 to_ndc) {
    keep_fragment_of(slot, p, node, capacity, to_ndc, 0u);
}

// The work group's room in the pool: `mine` nodes for this thread, the first returned. One
// atomic on the pool's counter a work group (its fragments one atomic each would wait on
// each other on that one counter). Every thread of the work group calls it.
shared uint group_nodes;
shared uint group_first_node;
uint take_nodes(uint mine) {
    if (gl_LocalInvocationIndex == 0u) {
        group_nodes = 0u;
    }
    barrier();
    uint before = subgroupExclusiveAdd(mine), total = subgroupAdd(mine);
    uint base = 0u;
    if (subgroupElect() && total > 0u) {
        base = atomicAdd(group_nodes, total);
    }
    base = subgroupBroadcastFirst(base);
    barrier();
    if (gl_LocalInvocationIndex == 0u && group_nodes > 0u) {
        group_first_node = atomicAdd(layer_counts.x, group_nodes);
    }
    barrier();
    return group_first_node + base + before;
}

#endif
