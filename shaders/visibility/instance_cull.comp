#version 450
#extension GL_GOOGLE_include_directive : require
// Culling, step 1 (once a frame, before the early phase): every instance (object) against the
// view frustum; the survivors' indices go to the visible-instance list, whose length is the
// meshlet culling's work-group count (an indirect dispatch).
#include "common/common.glsl"

layout(local_size_x = 64) in;

// Transparent objects are blended in layers (transparency/layers.glsl), not drawn here —
// but for their cores (BLENDED_CORES).
layout(constant_id = 20) const bool SKIP_BLENDED = false;

#include "visibility/meshlet_cull.glsl"
#include "common/blended_cores.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i == 0u) {
        // The indirect dispatches' other sizes and the draws' instance counts (the rest of
        // the counters start at 0).
        counters.dispatch.yz = uvec2(1u);
        counters.meshlets[0].yz = uvec2(1u);
        counters.meshlets[1].yz = uvec2(1u);
        counters.draws[0].instance_count = 1u;
        counters.draws[1].instance_count = 1u;
    }
    if (i >= instances.length()) {
        return;
    }
    atomicAdd(counters.tested.z, 1u);
    uint flags = objects[i].alpha_texture.x;
    if (SKIP_BLENDED && (flags & OBJECT_BLENDED) != 0u && !(BLENDED_CORES && (flags & OBJECT_CORE) != 0u)) {
        return;
    }
    vec4 b = instances[i].bounds;
    if (opaque_uniform(cull.mode.y) == 0u || sphere_in_frustum(b.xyz, b.w)) {
        visible_instances[atomicAdd(counters.dispatch.x, 1u)] = i;
    }
}
