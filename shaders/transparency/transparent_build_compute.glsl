// The transparent layers' build in compute, for transparent objects of few triangles (glass
// panes, windows, cards): the H100 runs fragment shaders on 4 of its 132 SMs. One dispatch
// for all of them (per texture set), a work group per 16×16-pixel tile, which
// - lists the objects whose screen rectangle (found on the CPU) meets the tile, 64 at a time;
// - sets their triangles up, 64 at a time, a thread each, in shared memory (clip-space edge
//   functions, attributes, the object's alpha and material);
// - counts its pixels' fragments of them (a bit per triangle and pixel), takes room for all with
//   one atomic on the pool, then writes the nodes of those bits, neighbours of one triangle side
//   by side (the resolve's lighting reads them a thread each, in that order);
// - links each pixel's new nodes in front of its list in a register and stores the head once.
// So a fragment costs no global atomic and no read of its head, and a tile's setup is paid
// once for every object over it. The tile is large because the setup's shared memory, not the
// threads, bounds how many work groups an SM holds, and the tests wait on shared loads: with
// 8×8 tiles the 24-pane stress took 3.6 ms (1.1 ms at 16×16); a dispatch per object, 4.7 ms.
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
// The includer defines OPAQUE_DEPTH_BUFFER for the compute raster's 64-bit buffer.
#define SURFACE_GRADIENTS 1
#include "common/common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;

#include "common/scene_bindings.glsl"
#include "common/textures.glsl"
#include "common/surface.glsl"
#define ALPHA_MASK_BINDING 11
#include "common/alpha_mask.glsl"
#define LAYER_BINDING 14
#include "transparency/layers.glsl"
#include "common/opaque_depth.glsl"

// The small meshes one after another (gpu_mesh.rs: 12 floats a vertex, position, normal, uv,
// tangent; three indices a triangle, each from its mesh's first vertex), and this frame's
// objects, those of one texture set side by side.
layout(std430, set = 3, binding = 0) readonly buffer MeshVertexBuffer { float mesh_vertices[]; };
layout(std430, set = 3, binding = 1) readonly buffer MeshIndexBuffer { uint mesh_indices[]; };
layout(std430, set = 3, binding = 2) readonly buffer LayerObjectBuffer { LayerObject layer_objects[]; };
// x: the dispatch's first object in layer_objects, y: its objects; z: the first pixel of the
// rectangle it covers (y << 16 | x, each a multiple of the tile's size).
layout(push_constant) uniform LayerDispatchBlock { uvec4 dispatch_objects; };

const uint CHUNK = 64u;
const uvec2 TILE = uvec2(16u);
// The tile's objects among the CHUNK being listed, and their triangles numbered in a row.
shared uint tile_objects[CHUNK];
shared uint tile_object_count;
shared uint tile_first_triangle[CHUNK + 1u];
// CHUNK of those triangles, set up: edge functions (rows of adj(M), times the sign of det(M)),
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
// The chunk's fragments in the tile, and the first of the nodes taken for them.
shared uint tile_fragments;
shared uint tile_taken;
shared uint tile_first_node;

const uint TRIANGLE_DRAWN = 1u; // faces a way its object is drawn from (and is not degenerate)
const uint TRIANGLE_FRONT = 2u; // faces the viewer

struct Vtx {
    vec3 position;
    vec3 normal;
    vec2 uv;
    vec4 tangent;
};

Vtx mesh_vertex(uint i) {
    uint b = 12u * i;
    Vtx v;
    v.position = vec3(mesh_vertices[b], mesh_vertices[b + 1u], mesh_vertices[b + 2u]);
    v.normal = vec3(mesh_vertices[b + 3u], mesh_vertices[b + 4u], mesh_vertices[b + 5u]);
    v.uv = vec2(mesh_vertices[b + 6u], mesh_vertices[b + 7u]);
    v.tangent = vec4(mesh_vertices[b + 8u], mesh_vertices[b + 9u], mesh_vertices[b + 10u], mesh_vertices[b + 11u]);
    return v;
}

// Set up triangle `t` (numbered over the tile's objects) in place `slot`.
void set_up_triangle(uint slot, uint t) {
    uint k = 0u;
    while (tile_first_triangle[k + 1u] <= t) {
        k++;
    }
    LayerObject entry = layer_objects[tile_objects[k]];
    uint o = entry.ids.x;
    mat4 model = objects[o].model;
    mat3 normal_matrix = mat3(objects[o].normal_matrix);
    vec4 uv_transform[2] = objects[o].uv_transform;
    mat4 view_proj = frame.proj * frame.view;
    uint first = entry.ids.z + 3u * (t - tile_first_triangle[k]);
    vec4 clip[3];
    for (uint v = 0u; v < 3u; v++) {
        Vtx x = mesh_vertex(entry.place.x + mesh_indices[first + v]);
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
    tri_object[slot] = uvec3(o, (drawn ? TRIANGLE_DRAWN : 0u) | (front ? TRIANGLE_FRONT : 0u), entry.ids.y);
    tri_alpha[slot] = objects[o].alpha.y;
    tri_alpha_texture[slot] = alpha_texture;
    tri_material[slot] = objects[o].material;
}

// Whether a pixel where edge function `e` (coefficients `c`) is 0 belongs to this triangle.
bool edge_owns(float e, vec2 c) {
    return e > 0.0 || (e == 0.0 && (c.x > 0.0 || (c.x == 0.0 && c.y > 0.0)));
}

// The barycentrics of point `q` (x, y in NDC, 1) on triangle `i`'s plane.
vec3 barycentrics(uint i, vec3 q) {
    vec3 e = vec3(dot(tri_edges[i][0], q), dot(tri_edges[i][1], q), dot(tri_edges[i][2], q));
    return e / (e.x + e.y + e.z);
}

// Whether triangle `i` leaves a fragment at `q` in front of `opaque`: its barycentrics,
// depth and coverage.
bool layer_fragment(uint i, vec3 q, float opaque, out vec3 w, out float depth, out float alpha) {
    w = vec3(0.0);
    depth = 0.0;
    alpha = 0.0;
    if ((tri_object[i].y & TRIANGLE_DRAWN) == 0u) {
        return false;
    }
    vec3 e = vec3(dot(tri_edges[i][0], q), dot(tri_edges[i][1], q), dot(tri_edges[i][2], q));
    if (!(edge_owns(e.x, tri_edges[i][0].xy) && edge_owns(e.y, tri_edges[i][1].xy) && edge_owns(e.z, tri_edges[i][2].xy))) {
        return false;
    }
    float sum = e.x + e.y + e.z;
    if (sum <= 0.0) {
        return false;
    }
    w = e / sum;
    depth = dot(w, tri_z[i]) / dot(w, tri_w[i]);
    if (!(depth >= 0.0 && depth <= 1.0) || depth >= opaque) {
        return false;
    }
    alpha = tri_alpha[i];
    if ((tri_alpha_texture[i].x & OBJECT_ALPHA_TEXTURE) != 0u) {
        alpha *= texture_alpha(tri_alpha_texture[i], w.x * tri_uv[i][0] + w.y * tri_uv[i][1] + w.z * tri_uv[i][2]);
    }
    return alpha > 0.0;
}

// The surface of triangle `i` at barycentrics `w` (pixel `q`), packed for its node.
uvec4 layer_surface(uint i, vec3 q, vec3 w, float alpha, vec2 to_ndc) {
    vec2 uv = w.x * tri_uv[i][0] + w.y * tri_uv[i][1] + w.z * tri_uv[i][2];
    // The texture coordinates one pixel to the right and one down.
    vec3 wx = barycentrics(i, q + vec3(to_ndc.x, 0.0, 0.0)), wy = barycentrics(i, q + vec3(0.0, to_ndc.y, 0.0));
    surface_uv_dx = wx.x * tri_uv[i][0] + wx.y * tri_uv[i][1] + wx.z * tri_uv[i][2] - uv;
    surface_uv_dy = wy.x * tri_uv[i][0] + wy.y * tri_uv[i][1] + wy.z * tri_uv[i][2] - uv;
    vec3 n = w.x * tri_normal[i][0] + w.y * tri_normal[i][1] + w.z * tri_normal[i][2];
    vec4 tangent = w.x * tri_tangent[i][0] + w.y * tri_tangent[i][1] + w.z * tri_tangent[i][2];
    bool front = (tri_object[i].y & TRIANGLE_FRONT) != 0u;
    Surface sf = surface_at(front ? n : -n, tangent, uv, tri_object[i].z, tri_material[i]);
    return pack_layer_surface(sf.normal, vec4(sf.albedo_factor, sf.occlusion), sf.roughness_metallic, min(alpha, 1.0), sf.emissive_factor);
}

void main() {
    uint lid = gl_LocalInvocationIndex;
    uvec2 tile = uvec2(dispatch_objects.z & 0xffffu, dispatch_objects.z >> 16) + gl_WorkGroupID.xy * TILE;
    ivec2 p = ivec2(tile + gl_LocalInvocationID.xy);
    bool in_image = p.x < int(frame.viewport.x) && p.y < int(frame.viewport.y);
    uint pixel = in_image ? layer_pixel(p) : 0u;
    // The pixel's list: its new nodes go in front.
    uint first_head = in_image ? layer_heads[pixel] : LAYER_END;
    uint head = first_head;
    float opaque = in_image ? opaque_depth_at(p) : 0.0;
    vec2 to_ndc = 2.0 / vec2(frame.viewport.xy);
    vec3 q = vec3((vec2(p) + 0.5) * to_ndc - 1.0, 1.0);
    uint capacity = layer_capacity();
    for (uint listed = 0u; listed < opaque_uniform(dispatch_objects.y); listed += CHUNK) {
        if (lid == 0u) {
            tile_object_count = 0u;
        }
        barrier();
        uint e = dispatch_objects.x + listed + lid;
        if (lid < CHUNK && listed + lid < dispatch_objects.y) {
            uvec4 place = layer_objects[e].place;
            uvec2 lo = uvec2(place.y & 0xffffu, place.y >> 16), end = uvec2(place.z & 0xffffu, place.z >> 16);
            if (all(lessThan(lo, tile + TILE)) && all(lessThan(tile, end))) {
                tile_objects[atomicAdd(tile_object_count, 1u)] = e;
            }
        }
        barrier();
        if (lid == 0u) {
            uint sum = 0u;
            for (uint k = 0u; k < tile_object_count; k++) {
                tile_first_triangle[k] = sum;
                sum += layer_objects[tile_objects[k]].ids.w;
            }
            tile_first_triangle[tile_object_count] = sum;
        }
        barrier();
        uint triangles = tile_first_triangle[tile_object_count];
        for (uint base = 0u; base < triangles; base += CHUNK) {
            if (lid == 0u) {
                tile_fragments = 0u;
                tile_taken = 0u;
            }
            if (lid < CHUNK && base + lid < triangles) {
                set_up_triangle(lid, base + lid);
            }
            barrier();
            uint count = min(CHUNK, triangles - base);
            // Which of the chunk's triangles leave a fragment here, a bit each: the writes below
            // follow these bits, not a second test, so they take exactly the room counted
            // (a compiler may evaluate two copies of a test with different rounding).
            uvec2 hits = uvec2(0u);
            vec3 w;
            float depth, alpha;
            for (uint i = 0u; i < count && in_image; i++) {
                if (layer_fragment(i, q, opaque, w, depth, alpha)) {
                    hits[i >> 5] |= 1u << (i & 31u);
                }
            }
            uint mine = uint(bitCount(hits.x) + bitCount(hits.y));
            if (mine > 0u) {
                atomicAdd(tile_fragments, mine);
            }
            barrier();
            if (lid == 0u && tile_fragments > 0u) {
                tile_first_node = atomicAdd(layer_counts.x, tile_fragments);
            }
            barrier();
            for (uint i = 0u; i < count && mine > 0u; i++) {
                if ((hits[i >> 5] & (1u << (i & 31u))) != 0u) {
                    // Its barycentrics, depth and coverage again (not kept from the count: 64
                    // triangles' worth of registers).
                    layer_fragment(i, q, opaque, w, depth, alpha);
                    uint node = tile_first_node + atomicAdd(tile_taken, 1u);
                    if (node < capacity) {
                        write_layer(node, p, depth, head, tri_object[i].x, layer_surface(i, q, w, alpha, to_ndc));
                        head = node;
                    }
                }
            }
            // Before the next chunk's setup.
            barrier();
        }
        // Before the next objects are listed.
        barrier();
    }
    if (head != first_head) {
        layer_heads[pixel] = head;
    }
}
