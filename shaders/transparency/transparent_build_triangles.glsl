// The transparent layers' build a thread per triangle, for transparent objects of many
// triangles (foliage, hair cards, particles): its cost follows triangles and fragments, where
// the tiles' build (transparent_build_compute.glsl) tests every triangle over a tile at each
// of the tile's pixels. One dispatch per texture set over its objects' triangles (in pieces
// of at most 65,535 work groups). A thread sets its triangle up in its own place of
// layer_triangles.glsl's shared arrays — the same set-up, coverage and surface as the other
// builds', so the same fragments bit for bit — and walks the pixels of its box, up to
// THREAD_BOX a side. Larger triangles are listed for a work group each
// (transparent_build_large.glsl), up to GROUP_BOX a side; larger still for the tiles' build,
// which scans them at every tile of the image: few triangles are that large. Both run after
// this dispatch, with the work groups it counts.
//
// A thread first marks the pixels of its box its triangle leaves a fragment at, then takes
// room for all of them (take_nodes: one atomic on the pool a work group), then writes them.
//
// The includer defines OPAQUE_DEPTH_BUFFER for the compute raster's 64-bit buffer.
#include "common/common.glsl"

layout(local_size_x = 64) in;

#include "transparency/layer_triangles.glsl"

// The largest box, in pixels a side, a thread walks (a work group: GROUP_BOX); the words of
// a thread's box's bits.
const int THREAD_BOX = 16;
const uint BOX_WORDS = uint(THREAD_BOX * THREAD_BOX) / 32u;

// The entry among the dispatch's `entries` from `first` whose triangles hold triangle `t`
// (entries list their first triangle, counted over the dispatch, in place.w).
uint entry_of(uint t, uint first, uint entries) {
    uint lo = first, hi = first + entries - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) >> 1;
        if (layer_objects[mid].place.w <= t) {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    return lo;
}

void main() {
    uint lid = gl_LocalInvocationIndex;
    uint first = opaque_uniform(dispatch_objects.x), entries = opaque_uniform(dispatch_objects.y);
    uint triangles = opaque_uniform(dispatch_objects.z), list_slot = opaque_uniform(dispatch_objects.w) - 1u;
    uint room_first = opaque_uniform(large_list.x), room = opaque_uniform(large_list.y);
    // The dispatch's piece of the texture set's triangles starts at large_list.z.
    uint t = opaque_uniform(large_list.z) + gl_GlobalInvocationID.x;
    ivec4 box = ivec4(0, 0, -1, -1);
    if (t < triangles) {
        LayerObject entry = layer_objects[entry_of(t, first, entries)];
        uint k = t - entry.place.w;
        set_up_triangle(lid, entry, k, box);
        ivec2 size = box.zw - box.xy + 1;
        if ((tri_object[lid].y & TRIANGLE_DRAWN) == 0u || any(lessThanEqual(size, ivec2(0)))) {
            box = ivec4(0, 0, -1, -1);
        } else if (any(greaterThan(size, ivec2(THREAD_BOX)))) {
            // Listed alone, its box the rectangle (whose end is exclusive): for a work group,
            // from the room's start; huge, for the tiles, from its end. Each list's dispatch
            // gets its work groups: a group a triangle (at most Vulkan's least limit; they
            // stride), every tile column once one triangle is huge.
            uint counts = LIST_WORDS * list_slot;
            uint at;
            if (any(greaterThan(size, ivec2(GROUP_BOX)))) {
                at = room - 1u - atomicAdd(large_triangles[counts + LIST_HUGE], 1u);
                atomicAdd(layer_counts.w, 1u);
                atomicMax(large_triangles[counts + LIST_HUGE_GROUPS], (frame.viewport.x + LAYER_TILE - 1u) / LAYER_TILE);
            } else {
                uint listed = atomicAdd(large_triangles[counts + LIST_LARGE], 1u);
                atomicAdd(layer_counts.z, 1u);
                atomicMax(large_triangles[counts + LIST_LARGE_GROUPS], min(listed + 1u, 65535u));
                at = listed;
            }
            uvec4 ids = uvec4(entry.ids.xy, entry.ids.z + 3u * k, 1u);
            uvec2 lo = uvec2(box.xy), end = uvec2(box.zw + 1);
            layer_objects[room_first + at] = LayerObject(ids, uvec4(entry.place.x, lo.y << 16 | lo.x, end.y << 16 | end.x, 0u));
            box = ivec4(0, 0, -1, -1);
        }
    }
    // The box's pixels a fragment is left at, a bit each (THREAD_BOX² at most), then room
    // for all of them and their nodes.
    int width = max(box.z - box.x + 1, 1);
    int pixels = max(box.z - box.x + 1, 0) * max(box.w - box.y + 1, 0);
    vec2 to_ndc = 2.0 / vec2(frame.viewport.xy);
    uint hits[BOX_WORDS];
    for (uint k = 0u; k < BOX_WORDS; k++) {
        hits[k] = 0u;
    }
    uint mine = 0u;
    for (int i = 0; i < pixels; i++) {
        if (pixel_fragment(lid, box.xy + ivec2(i % width, i / width), to_ndc)) {
            hits[i >> 5] |= 1u << (i & 31);
            mine++;
        }
    }
    uint node = take_nodes(mine);
    uint capacity = layer_capacity();
    for (uint k = 0u; k < BOX_WORDS && mine > 0u; k++) {
        for (uint bits = hits[k]; bits != 0u; bits &= bits - 1u) {
            int i = int(32u * k) + findLSB(bits);
            keep_fragment(lid, box.xy + ivec2(i % width, i / width), node++, capacity, to_ndc);
        }
    }
}
