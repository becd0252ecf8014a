#version 450
#extension GL_GOOGLE_include_directive : require
// The light grid's build, one invocation per light, run twice around the scan
// (light_grid_scan.comp):
//   COUNT: move the light by the frame's offset, find its list (its cell, or the wide
//          lights' when wider than the reach) and count it there;
//   FILL:  after the scan, take the next place of its list and write its index there. The
//          lists' counters end as each cell's end (light_grid.glsl reads them so).
// Keep the list choice in sync with crates/ml-cpu/src/light_grid.rs (list_of).
#include "common/common.glsl"

layout(local_size_x = 256) in;
layout(constant_id = 0) const bool FILL = false;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
// The lights at rest in the grid's order (that of their cells at rest, so that neighbouring
// invocations count into neighbouring cells): xyz position, w radius.
layout(std430, set = 0, binding = 1) readonly buffer LightGridRestBuffer { vec4 rest_positions[]; };
// Per list: COUNT its count; after the scan its start, after FILL its end (block-relative).
layout(std430, set = 0, binding = 3) buffer LightGridCellBuffer { uint grid_cell_ends[]; };
// Per block of lists: x its start in the index list.
layout(std430, set = 0, binding = 4) readonly buffer LightGridBlockBuffer { uvec2 grid_blocks[]; };
// Per light: its list, from COUNT to FILL.
layout(std430, set = 0, binding = 5) buffer LightGridListOfBuffer { uint list_of[]; };
layout(std430, set = 0, binding = 6) writeonly buffer LightGridIndexBuffer { uint grid_lights[]; };

const uint GRID_BLOCK = 1024u;

void main() {
    // Work groups come in rows (a device takes at most 65,535 along x).
    uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
    if (i >= frame.light_count) {
        return;
    }
    if (FILL) {
        uint list = list_of[i];
        uint slot = grid_blocks[list / GRID_BLOCK].x + atomicAdd(grid_cell_ends[list], 1u);
        grid_lights[slot] = i;
        return;
    }
    vec4 light = rest_positions[i];
    light.xyz += frame.light_animation.xyz;
    uint list = frame.light_grid_dims.w;
    if (light.w <= frame.light_grid_reach.x) {
        vec3 g = (light.xyz - frame.light_grid_origin.xyz) * frame.light_grid_origin.w;
        uvec3 c = uvec3(clamp(floor(g), vec3(0.0), vec3(frame.light_grid_dims.xyz - 1u)));
        list = (c.z * frame.light_grid_dims.y + c.y) * frame.light_grid_dims.x + c.x;
    }
    list_of[i] = list;
    atomicAdd(grid_cell_ends[list], 1u);
}
