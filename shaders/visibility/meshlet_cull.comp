#version 450
#extension GL_GOOGLE_include_directive : require
// Culling, step 2, a work group per instance that passed the frustum test, a thread per
// meshlet, in two phases (docs/DESIGN.md#gpu-culling); the meshlets drawn get a draw slot
// each, whose triangles triangle_cull.comp tests next:
//  early: meshlets visible at the end of the last frame, tested against the frustum and
//         their back-face cones, are drawn first;
//  late:  after the depth pyramid of what the early draws left, every meshlet is tested
//         again, now also for occlusion; those visible and not drawn early are drawn, and
//         every meshlet's visibility is kept for the next frame.
// Nothing pops: whatever the early phase missed, the late phase finds against this frame's
// own depth. Culling off: the early phase draws every meshlet, the late phase nothing.
#include "common/common.glsl"

layout(local_size_x = 64) in;

#include "visibility/meshlet_cull.glsl"

void main() {
    uint instance = visible_instances[gl_WorkGroupID.x];
    Instance inst = instances[instance];
    mat4 model = objects[instance].model;
    bool late = opaque_uniform(cull.mode.x) == 1u;
    bool culling = opaque_uniform(cull.mode.y) != 0u;
    if (late && gl_GlobalInvocationID.x == 0u) {
        // The early triangles are all compacted by now: the late ones follow them.
        counters.draws[1].first_index = counters.draws[0].index_count;
    }
    for (uint k = gl_LocalInvocationID.x; k < inst.meshlets.y; k += gl_WorkGroupSize.x) {
        uint id = inst.meshlets.z + k;
        Meshlet m = meshlets[inst.meshlets.x + k];
        bool draw;
        if (!culling) {
            draw = !late;
        } else {
            bool was_visible = meshlet_visible[id] != 0u;
            if (!late && !was_visible) {
                continue;
            }
            if (late) {
                atomicAdd(counters.tested.y, 1u);
            } else {
                atomicAdd(counters.tested.x, 1u);
            }
            vec3 c = (model * vec4(m.center_radius.xyz, 1.0)).xyz;
            float r = m.center_radius.w * inst.scale.x;
            bool visible = sphere_in_frustum(c, r) && !meshlet_backfacing(m, model, inst.meshlets.w);
            if (late) {
                visible = visible && !sphere_occluded(c, r);
                meshlet_visible[id] = visible ? 1u : 0u;
                draw = visible && !was_visible;
            } else {
                draw = visible;
            }
        }
        if (draw) {
            uint slot;
            if (late) {
                slot = cull.mode.w + atomicAdd(counters.meshlets[1].x, 1u);
                atomicAdd(counters.triangles.y, m.triangles.y);
            } else {
                slot = atomicAdd(counters.meshlets[0].x, 1u);
                atomicAdd(counters.triangles.x, m.triangles.y);
            }
            draw_slots[slot] = uvec4(id, instance, m.triangles.z, inst.meshlets.x + k);
        }
    }
}
