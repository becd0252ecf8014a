#version 450
#extension GL_GOOGLE_include_directive : require
// Traces a list of segments through the shadow rays' hierarchy (shadow_rays.glsl), for the
// test that holds the GLSL traversal to the CPU's (tests/shadow_ray_traversal.rs): per segment 1 if a
// triangle blocks it.
#include "common/common.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer RayTopBuffer { RayNode ray_top[]; };
layout(std430, set = 0, binding = 1) readonly buffer RayNodeBuffer { RayNode ray_nodes[]; };
layout(std430, set = 0, binding = 2) readonly buffer RayTriangleBuffer { RayTriangle ray_triangles[]; };
layout(std430, set = 0, binding = 3) readonly buffer RayInstanceBuffer { RayInstance ray_instances[]; };
// Per segment: its two ends (xyz; w unused).
layout(std430, set = 0, binding = 4) readonly buffer SegmentBuffer { vec4 segments[]; };
layout(std430, set = 0, binding = 5) writeonly buffer BlockedBuffer { uint blocked[]; };

#include "shadows/shadow_rays.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (2u * i + 1u < uint(segments.length())) {
        blocked[i] = ray_occluded(segments[2u * i].xyz, segments[2u * i + 1u].xyz) ? 1u : 0u;
    }
}
