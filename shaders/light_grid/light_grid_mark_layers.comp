#version 450
#extension GL_GOOGLE_include_directive : require
// The light grid's marks of the transparent layers' points (after the opaque depth's marks,
// light_grid_mark.glsl): a thread per node the build kept marks the cells its point's walk
// will visit when the resolve lights it (layers.glsl light_layer finds it the same way).
#include "common/common.glsl"

layout(local_size_x = 256) in;

FRAME_BLOCK(0);
layout(std430, set = 0, binding = 31) coherent buffer LightGridOccupancyBuffer { uvec2 grid_occupancy[]; };
#define LAYER_BINDING 20
#include "transparency/layers.glsl"
#include "light_grid/light_grid_marking.glsl"

void main() {
    uint kept = min(layer_counts.x, layer_capacity());
    for (uint node = gl_GlobalInvocationID.x; node < kept; node += gl_NumWorkGroups.x * gl_WorkGroupSize.x) {
        uvec4 a = layer_nodes[LAYER_NODE_WORDS * node];
        mark_walk(world_from_depth(layer_xy(a), uintBitsToFloat(a.x)));
    }
}
