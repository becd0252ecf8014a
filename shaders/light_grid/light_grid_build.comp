#version 450
#extension GL_GOOGLE_include_directive : require
// The light grid's build, after the scan of the marks (light_grid_scan.comp: the marked
// cells' lists numbered, their counts zeroed), an invocation per light, twice around the
// scan of the lists:
//   COUNT: find the light's list: the wide lights' (list 0) for the last `wide` of the grid's
//          order, else, moved by the frame's offset, its cell's if the cell is marked
//          (light_grid_mark.glsl; otherwise no pixel tests it and it is left out). Count it
//          there and keep (light, list) in the work group's part of the kept lights;
//   FILL:  after the scan, each kept light takes the next place of its list and writes itself
//          there, moved: position and radius, colour, index in the scene.
// Keep the list choice in sync with crates/ml-cpu/src/light_grid.rs (list_of).
#include "common/common.glsl"

layout(local_size_x = 256) in;
// 0: COUNT, 1: FILL.
layout(constant_id = 0) const uint STEP = 0u;

FRAME_BLOCK(0);
#include "light_grid/light_grid_walk.glsl"
// The lights at rest in the grid's order (that of their cells at rest, so that neighbouring
// invocations count into neighbouring cells; the wide lights last): positions alone, packed
// (x, y, z of light i at 3i: twelve bytes a light, what COUNT reads of every light); and whole.
layout(std430, set = 0, binding = 1) readonly buffer LightGridRestBuffer { float rest_positions[]; };
layout(std430, set = 0, binding = 2) readonly buffer LightGridRestLightBuffer { PointLight rest_lights[]; };
// Per place of the grid's order: the light's index in the scene.
layout(std430, set = 0, binding = 9) readonly buffer LightGridOrderBuffer { uint grid_order[]; };
// Per list: COUNT its count; after the scan its start (FILL's cursor); after FILL its end
// (what the walk reads, light_grid.glsl).
layout(std430, set = 0, binding = 3) buffer LightGridListBuffer { uint grid_lists[]; };
// Per 32 cells: their marks and the list of the first marked one.
layout(std430, set = 0, binding = 4) readonly buffer LightGridOccupancyBuffer { uvec2 grid_occupancy[]; };
// Per work group of COUNT: its kept lights (place in the grid's order, list) and how many.
layout(std430, set = 0, binding = 5) buffer LightGridKeptBuffer { uvec2 kept[]; };
layout(std430, set = 0, binding = 10) buffer LightGridKeptCountBuffer { uint kept_count[]; };
// The lists: each light moved (position and radius; colour), and its index in the scene.
layout(std430, set = 0, binding = 6) writeonly buffer LightGridPositionBuffer { vec4 grid_light_positions[]; };
layout(std430, set = 0, binding = 14) writeonly buffer LightGridColorBuffer { vec4 grid_light_colors[]; };
layout(std430, set = 0, binding = 11) writeonly buffer LightGridIndexBuffer { uint grid_scene_index[]; };

shared uint group_kept;

// Whether cell c is marked, and its list.
bool marked_list(uint c, out uint list) {
    uvec2 o = grid_occupancy[c >> 5u];
    list = grid_word_list(o, c);
    return (o.x & (1u << (c & 31u))) != 0u;
}

void main() {
    // Work groups come in rows (a device takes at most 65,535 along x).
    uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint t = gl_LocalInvocationID.x;
    uint first = group * gl_WorkGroupSize.x;
    if (STEP == 1u) {
        if (t >= kept_count[group]) {
            return;
        }
        uvec2 k = kept[first + t];
        uint slot = atomicAdd(grid_lists[k.y], 1u);
        PointLight l = rest_lights[k.x];
        grid_light_positions[slot] = vec4(l.position_radius.xyz + frame.light_animation.xyz, l.position_radius.w);
        grid_light_colors[slot] = l.color;
        grid_scene_index[slot] = grid_order[k.x];
        return;
    }
    if (t == 0u) {
        group_kept = 0u;
    }
    barrier();
    uint i = first + t;
    if (i < frame.light_count) {
        bool listed = true;
        uint list = 0u;
        // The wide lights, last in the grid's order, go in list 0.
        if (i < frame.light_count - uint(frame.light_grid_reach.y)) {
            vec3 light = vec3(rest_positions[3u * i], rest_positions[3u * i + 1u], rest_positions[3u * i + 2u]);
            light += frame.light_animation.xyz;
            vec3 g = (light - frame.light_grid_origin.xyz) * frame.light_grid_origin.w;
            uvec3 c = uvec3(clamp(floor(g), vec3(0.0), vec3(frame.light_grid_dims.xyz - 1u)));
            listed = marked_list((c.z * frame.light_grid_dims.y + c.y) * frame.light_grid_dims.x + c.x, list);
        }
        if (listed) {
            atomicAdd(grid_lists[list], 1u);
            kept[first + atomicAdd(group_kept, 1u)] = uvec2(i, list);
        }
    }
    barrier();
    if (t == 0u) {
        kept_count[group] = group_kept;
    }
}
