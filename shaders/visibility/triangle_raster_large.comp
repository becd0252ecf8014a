#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
// The compute raster's large triangles (visibility_polygon.glsl): a work group per listed
// 64×64-pixel bin of a triangle's box, so a triangle covering the screen is spread over the
// whole GPU. The triangle was clipped and snapped once, when it was found; here the work group
// draws the bin's pixels for every fan triangle that reaches them, a sample a thread.
#include "common/common.glsl"

layout(local_size_x = 64) in;

FRAME_BLOCK(0);
layout(std430, set = 0, binding = 1) buffer CullCounterBuffer { CullCounters counters; };
layout(std430, set = 0, binding = 2) readonly buffer LargeBinBuffer { uvec2 large_bins[]; };
layout(std430, set = 0, binding = 3) buffer LargeTriangleBuffer { LargeTriangle large_triangles[]; };
layout(std430, set = 0, binding = 4) buffer VisibilityDepthBuffer { uint64_t visibility_depth[]; };
layout(std430, set = 0, binding = 5) readonly buffer ObjectBuffer { ObjectData objects[]; };
layout(push_constant) uniform CullPushBlock { CullPush cull; };

#define ALPHA_MASK_BINDING 6
#include "common/alpha_mask.glsl"
#include "common/blended_cores.glsl"
// The transparent layers' candidates (cores' soft samples).
#define LAYER_CANDIDATE_BINDING 7
#include "visibility/layer_candidates.glsl"
#include "visibility/visibility_polygon.glsl"

shared uint group_pixels;

void main() {
    uint lid = gl_LocalInvocationID.x;
    uint phase = opaque_uniform(cull.mode.x);
    uint count = min(counters.binned[phase], opaque_uniform(cull.triangles.z));
    ivec2 size = ivec2(frame.viewport.xy);
    if (lid == 0u) {
        group_pixels = 0u;
    }
    // Thread lid takes sample `own` of every lanes-th pixel of each row, so the atomics a
    // subgroup issues together fall on neighbouring pixels' samples, side by side in the
    // buffer: on the H200 the cost of 64-bit atomics follows the places in memory one
    // instruction touches (a thread per 8×8 block of pixels, each its own samples, took twice
    // as long). Every thread has as many points of a triangle's box to test.
    uint own = lid % VISIBILITY_SAMPLES;
    int lanes = int(gl_WorkGroupSize.x / VISIBILITY_SAMPLES), lane = int(lid / VISIBILITY_SAMPLES);
    uint covered = 0u;
    for (uint e = gl_WorkGroupID.x; e < count; e += gl_NumWorkGroups.x) {
        uvec2 listed = large_bins[e];
        if (listed.x == NO_BIN) {
            continue;
        }
        uint at = listed.x;
        uvec4 head = large_triangles[at].head;
        SurfaceTest surface = MASK_TESTS ? large_surface(at, head.z) : no_surface_test();
        bool both_faces = SURFACE_TESTS && (head.w & INSTANCE_DOUBLE_SIDED) != 0u;
        ivec2 bin = ivec2(listed.y & 0xffffu, listed.y >> 16u);
        ivec2 lo = bin * BIN, hi = lo + BIN - 1;
        i64vec2 s0 = large_corner(at, 0);
        vec4 q0 = large_depth(at, 0);
        // A core's soft samples listed where its triangle is whole (unclipped), else the cores
        // are left to the per-triangle build.
        bool listing = MASK_TESTS && head.z != NOT_MASKED && lists_candidates(objects[head.z].alpha_texture.x);
        if (listing && head.x != 3u) {
            if (lid == 0u) {
                leave_cores_to_the_triangles();
            }
            listing = false;
        }
        for (int k = 1; k + 1 < int(head.x); k++) {
            FanTriangle t;
            if (!fan_triangle(s0, large_corner(at, k), large_corner(at, k + 1), q0, large_depth(at, k), large_depth(at, k + 1), size, both_faces, t)) {
                continue;
            }
            ivec2 from = max(lo, t.first), to = min(hi, t.last);
            if (any(greaterThan(from, to)) || !fan_reaches(t, from, to)) {
                continue;
            }
            // From the first pixel of the row that is this thread's.
            from.x += ((lane - from.x % lanes) + lanes) % lanes;
            if (from.x <= to.x) {
                covered += fan_samples(t, from, to, lanes, own, head.y, surface, listing);
            }
        }
    }
    barrier();
    atomicAdd(group_pixels, covered);
    barrier();
    if (lid == 0u) {
        atomicAdd(counters.rasterized.z, group_pixels);
    }
}
