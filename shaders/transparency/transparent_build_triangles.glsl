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
// A thread's walk only notes where its triangle may leave a fragment (an edge test in
// registers); the tests that read memory (the opaque depth, the alpha texture) and the
// writes are dealt over the work group, a listed pixel a thread, in rounds (see main). A
// thread that tested its own box's pixels kept its subgroup waiting on the largest box and
// on each of its reads in turn: on the H200, 3.8 ms for a forest of a million leaves at
// 1080p, where the rounds take 2.15.
//
// The includer defines OPAQUE_DEPTH_BUFFER for the compute raster's 64-bit buffer.
#include "common/common.glsl"

// A work group's threads, and the triangles it sets up at once (a place each). On the H200
// the build slows sharply once a work group's shared memory passes about 24 KB (64 threads
// and 16 a round: 2.27 ms for the forest above, 20 a round: 4.1); 32 threads: 2.15.
layout(local_size_x = 32) in;
const uint BUILD_THREADS = gl_WorkGroupSize.x;
#define LAYER_SLOTS BUILD_THREADS

#include "transparency/layer_triangles.glsl"

// The largest box, in pixels a side, a thread walks (a work group: GROUP_BOX).
const int THREAD_BOX = 16;

// A round's list: the pixels (y << 16 | x) where the work group's triangles (their places,
// round_slot) may leave a fragment, up to ROUND_TAKE from each thread's walk; how many; and
// whether some thread's walk goes on. 16 a round measured best on the H200 (12: 2.27 ms
// for the forest above).
const uint ROUND_TAKE = 16u;
shared uint round_pixel[BUILD_THREADS * ROUND_TAKE];
shared uint round_slot[BUILD_THREADS * ROUND_TAKE];
shared uint round_count;
shared uint round_more;

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
#ifdef OPAQUE_DEPTH_BUFFER
    // Cores the compute raster listed as candidates are the candidates' build's.
    if (opaque_uniform(large_list.w) != 0u && opaque_uniform(counters.candidates.y) == 0u) {
        return;
    }
#endif
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
    // Rounds, the same for every thread: each walks on through its box, listing the pixels
    // whose centre (with anti-aliasing: some sample) its triangle may cover, up to
    // ROUND_TAKE; then the work group tests the listed pixels a thread each (pixel_fragment
    // decides, as in the other builds: the walk's filter only skips pixels it would refuse),
    // takes room for the fragments found and writes them.
    vec2 to_ndc = 2.0 / vec2(frame.viewport.xy);
    vec3 r0 = tri_edges[lid][0], r1 = tri_edges[lid][1], r2 = tri_edges[lid][2];
    // How much each edge function may grow from the centre to a sample (samples_outside's
    // bound); 0 without anti-aliasing, where the centre alone counts.
    vec3 reach = VISIBILITY_SAMPLES == 1u ? vec3(0.0) : vec3(edge_reach(r0, to_ndc), edge_reach(r1, to_ndc), edge_reach(r2, to_ndc));
    ivec2 at = box.xy;
    bool walking = box.x <= box.z && box.y <= box.w;
    uint capacity = layer_capacity();
    while (true) {
        if (lid == 0u) {
            round_count = 0u;
            round_more = 0u;
        }
        barrier();
        for (uint taken = 0u; walking && taken < ROUND_TAKE;) {
            vec3 q = vec3((vec2(at) + 0.5) * to_ndc - 1.0, 1.0);
            if (all(greaterThanEqual(vec3(dot(r0, q), dot(r1, q), dot(r2, q)) + reach, vec3(0.0)))) {
                uint e = atomicAdd(round_count, 1u);
                round_pixel[e] = uint(at.y) << 16 | uint(at.x);
                round_slot[e] = lid;
                taken++;
            }
            at.x++;
            if (at.x > box.z) {
                at = ivec2(box.x, at.y + 1);
                walking = at.y <= box.w;
            }
        }
        if (walking) {
            round_more = 1u;
        }
        barrier();
        uint listed = round_count;
        bool more = round_more != 0u;
        // This thread's share of the list: entries lid, lid + BUILD_THREADS, … (ROUND_TAKE
        // at most), a bit each where a fragment is left.
        uint found = 0u, mine = 0u;
        for (uint j = lid, r = 0u; j < listed; j += BUILD_THREADS, r++) {
            uint word = round_pixel[j];
            if (pixel_fragment(round_slot[j], ivec2(word & 0xffffu, word >> 16), to_ndc)) {
                found |= 1u << r;
                mine++;
            }
        }
        uint node = take_nodes(mine);
        for (uint bits = found; bits != 0u; bits &= bits - 1u) {
            uint j = lid + BUILD_THREADS * uint(findLSB(bits)), word = round_pixel[j];
            keep_fragment(round_slot[j], ivec2(word & 0xffffu, word >> 16), node++, capacity, to_ndc);
        }
        if (!more) {
            break;
        }
    }
}
