#version 450
#extension GL_GOOGLE_include_directive : require
// clustered-gpu, every frame: exclusive prefix sum of the per-cluster counts into
// (offset, count) ranges, in three steps so that it scales to a million clusters:
//   STEP 0, one workgroup per block of 1024 clusters: scan within the block (ranges get the
//           block-local offsets), write the block's total and largest count;
//   STEP 1, one workgroup: scan the block totals (at most 1024 blocks), report the entries the
//           frame needs and the largest cluster;
//   STEP 2, one invocation per cluster: add the block's offset; the counters become write
//           cursors for FILL. When the frame needs more than the capacity, ranges are cut to
//           fit (the frame is wrong and reported, but nothing reads or writes out of bounds).
#include "common/common.glsl"

layout(local_size_x = 1024) in;
layout(constant_id = 0) const uint STEP = 0u;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 4) buffer CounterBuffer { uint counters[]; };
layout(std430, set = 0, binding = 5) buffer ClusterRangeBuffer { ClusterRange cluster_ranges[]; };
layout(std430, set = 0, binding = 7) buffer FeedbackBuffer { ClusterFeedback feedback; };
// Per block: x = total, y = largest count; after STEP 1, x = the block's offset.
layout(std430, set = 0, binding = 8) buffer BlockBuffer { uvec2 blocks[]; };

const uint BLOCK = 1024u;
shared uint scan[BLOCK];
shared uint most[BLOCK];

// Inclusive Hillis-Steele scan of scan[] and max-reduction of most[] over the workgroup.
void scan_workgroup(uint t) {
    for (uint step = 1u; step < BLOCK; step <<= 1u) {
        uint add = t >= step ? scan[t - step] : 0u;
        uint m = t >= step ? most[t - step] : 0u;
        barrier();
        scan[t] += add;
        most[t] = max(most[t], m);
        barrier();
    }
}

void main() {
    uint n = frame.cluster_dims.x * frame.cluster_dims.y * frame.cluster_dims.z;
    uint t = gl_LocalInvocationID.x;
    if (STEP == 0u) {
        uint i = gl_GlobalInvocationID.x;
        uint count = i < n ? counters[i] : 0u;
        scan[t] = count;
        most[t] = count;
        barrier();
        scan_workgroup(t);
        if (i < n) {
            cluster_ranges[i] = ClusterRange(scan[t] - count, count);
        }
        if (t == BLOCK - 1u) {
            blocks[gl_WorkGroupID.x] = uvec2(scan[t], most[t]);
        }
    } else if (STEP == 1u) {
        uint block_count = (n + BLOCK - 1u) / BLOCK;
        uvec2 b = t < block_count ? blocks[t] : uvec2(0u);
        scan[t] = b.x;
        most[t] = b.y;
        barrier();
        scan_workgroup(t);
        if (t < block_count) {
            blocks[t].x = scan[t] - b.x;
        }
        if (t == BLOCK - 1u) {
            feedback.needed = scan[t];
            feedback.overflowed = scan[t] > frame.cluster_build.x ? 1u : 0u;
            feedback.max_count = most[t];
        }
    } else {
        uint i = gl_GlobalInvocationID.x;
        if (i >= n) {
            return;
        }
        uint offset = blocks[i / BLOCK].x + cluster_ranges[i].offset;
        uint count = cluster_ranges[i].count;
        uint capacity = frame.cluster_build.x;
        uint start = min(offset, capacity);
        cluster_ranges[i] = ClusterRange(start, min(offset + count, capacity) - start);
        counters[i] = offset;
    }
}
