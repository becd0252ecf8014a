#version 450
#extension GL_GOOGLE_include_directive : require
// A shader no pipeline runs: what the test that no shader branches on uniform values alone
// (ml-shaders, uniform_branches.rs) must find — a branch on a push constant and a loop up to a
// count in a uniform block, both of which lavapipe would inline, compiling the shader again at
// every bind.

#include "common/common.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0) uniform UniformBranchBlock { uvec4 counts; }; // x: the loop's count
layout(std430, set = 0, binding = 1) buffer ProbeValues { float probe_values[]; };
layout(push_constant) uniform UniformBranchPushBlock { uvec4 mode; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    float sum = probe_values[i];
    if (mode.x == 1u) {
        sum = sin(sum) * cos(sum * 3.0) + sqrt(abs(sum));
    }
    for (uint k = 0u; k < counts.x; ++k) {
        sum += probe_values[i + k + 1u] * float(k);
    }
    probe_values[i] = sum;
}
