// The transparent layers' build over tiles, for transparent objects of few triangles (glass
// panes, windows, cards) and for the huge triangles the per-triangle build
// (transparent_build_triangles.glsl) lists. One dispatch for all of
// them (per texture set), a work group per 16×16-pixel tile, which
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
// The includer defines OPAQUE_DEPTH_BUFFER for the compute raster's 64-bit buffer.
#include "common/common.glsl"

// A thread per pixel of a LAYER_TILE² tile.
layout(local_size_x = 16, local_size_y = 16) in;

#include "transparency/layer_triangles.glsl"

const uvec2 TILE = uvec2(LAYER_TILE);
// The tile's objects among the CHUNK being listed, and their triangles numbered in a row.
shared uint tile_objects[CHUNK];
shared uint tile_object_count;
shared uint tile_first_triangle[CHUNK + 1u];
// The chunk's fragments in the tile, and the first of the nodes taken for them.
shared uint tile_fragments;
shared uint tile_taken;
shared uint tile_first_node;

// Set up triangle `t` (numbered over the tile's objects) in place `slot`.
void set_up_tile_triangle(uint slot, uint t) {
    uint k = 0u;
    while (tile_first_triangle[k + 1u] <= t) {
        k++;
    }
    ivec4 box;
    set_up_triangle(slot, layer_objects[tile_objects[k]], t - tile_first_triangle[k], box);
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
    uint capacity = layer_capacity();
    // The CPU's objects, or the huge triangles the per-triangle build listed at the end of
    // its room.
    uint huge_list = opaque_uniform(dispatch_objects.w);
    uint entries = huge_list == 0u ? opaque_uniform(dispatch_objects.y) : large_triangles[LIST_WORDS * (huge_list - 1u) + LIST_HUGE];
    uint first_entry = huge_list == 0u ? opaque_uniform(dispatch_objects.x) : opaque_uniform(large_list.x + large_list.y) - entries;
    for (uint listed = 0u; listed < entries; listed += CHUNK) {
        if (lid == 0u) {
            tile_object_count = 0u;
        }
        barrier();
        uint e = first_entry + listed + lid;
        if (lid < CHUNK && listed + lid < entries) {
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
                set_up_tile_triangle(lid, base + lid);
            }
            barrier();
            uint count = min(CHUNK, triangles - base);
            // Which of the chunk's triangles leave a fragment here, a bit each: the writes below
            // follow these bits, not a second test, so they take exactly the room counted
            // (a compiler may evaluate two copies of a test with different rounding).
            uvec2 hits = uvec2(0u);
            vec3 q, w;
            float depth, alpha;
            uint covered;
            for (uint i = 0u; i < count && in_image; i++) {
                if (layer_fragment(i, p, to_ndc, opaque, q, covered, w, depth, alpha)) {
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
                    layer_fragment(i, p, to_ndc, opaque, q, covered, w, depth, alpha);
                    uint node = tile_first_node + atomicAdd(tile_taken, 1u);
                    if (node < capacity) {
                        write_layer(node, p, depth, head, tri_object[i].x, covered, layer_surface(i, q, w, alpha, to_ndc));
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
