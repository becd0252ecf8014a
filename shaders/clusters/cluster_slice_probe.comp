#version 450
#extension GL_GOOGLE_include_directive : require
// Test probe: the GLSL slice formula on a list of depths, so a test can compare it with the
// CPU's (crates/ml-render/tests/cluster_slice.rs).
#include "common/common.glsl"
#include "clusters/cluster.glsl"

layout(local_size_x = 64) in;
FRAME_BLOCK(0);
layout(std430, set = 0, binding = 1) readonly buffer DepthBuffer { float depths[]; };
layout(std430, set = 0, binding = 2) writeonly buffer SliceBuffer { uint slices[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < depths.length()) {
        slices[i] = cluster_slice(frame, depths[i]);
    }
}
