#version 450
#extension GL_GOOGLE_include_directive : require
// clustered-gpu, every frame, one workgroup: exclusive prefix sum of the per-cluster counts
// into (offset, count) ranges; the counters become write cursors for the FILL pass. Reports
// how many list entries the frame needs; when that exceeds the capacity, ranges are cut to
// fit (the frame is wrong and reported, but nothing reads or writes out of bounds).
#include "common.glsl"

layout(local_size_x = 1024) in;
layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 4) buffer CounterBuffer { uint counters[]; };
layout(std430, set = 0, binding = 5) writeonly buffer ClusterRangeBuffer { ClusterRange cluster_ranges[]; };
layout(std430, set = 0, binding = 7) buffer FeedbackBuffer { ClusterFeedback feedback; };

shared uint partial[1024];
shared uint most;

void main() {
    uint n = frame.cluster_dims.x * frame.cluster_dims.y * frame.cluster_dims.z;
    uint t = gl_LocalInvocationID.x;
    uint per = (n + 1023u) / 1024u;
    uint first = min(t * per, n);
    uint last = min(first + per, n);
    if (t == 0u) {
        most = 0u;
    }
    barrier();
    uint sum = 0u;
    uint local_most = 0u;
    for (uint i = first; i < last; ++i) {
        sum += counters[i];
        local_most = max(local_most, counters[i]);
    }
    partial[t] = sum;
    atomicMax(most, local_most);
    barrier();
    // Hillis-Steele inclusive scan of the 1024 partial sums.
    for (uint step = 1u; step < 1024u; step <<= 1u) {
        uint add = t >= step ? partial[t - step] : 0u;
        barrier();
        partial[t] += add;
        barrier();
    }
    uint offset = partial[t] - sum;
    uint capacity = frame.cluster_build.x;
    for (uint i = first; i < last; ++i) {
        uint count = counters[i];
        uint start = min(offset, capacity);
        cluster_ranges[i] = ClusterRange(start, min(offset + count, capacity) - start);
        counters[i] = offset;
        offset += count;
    }
    if (t == 1023u) {
        uint total = partial[1023];
        feedback.needed = total;
        feedback.overflowed = total > capacity ? 1u : 0u;
        feedback.max_count = most;
    }
}
