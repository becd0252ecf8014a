// The light grid's marks (docs/DESIGN.md#the-light-grid): once the frame's opaque surfaces are
// known and before the build, a thread per pixel with a surface marks the cells its point's
// walk will visit (light_grid_walk.glsl). The build then lists only the lights of marked cells:
// a light whose cell no walk visits is tested by no pixel, so leaving it out changes nothing,
// and the lights far from every visible surface (most of them, at millions) cost the build a
// read and no more, and the lists hold only what the frame's pixels may test.
//
// The includer defines OPAQUE_DEPTH_BUFFER for the compute raster's 64-bit buffer.
#include "common/common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
// Per 32 cells: x their marks (bit c % 32 for cell c); y is the build's.
layout(std430, set = 0, binding = 31) buffer LightGridOccupancyBuffer { uvec2 grid_occupancy[]; };

#include "common/opaque_depth.glsl"
#include "common/world_from_depth.glsl"
#include "light_grid/light_grid_walk.glsl"

// Cells beyond the walk's reach a mark adds: the shading passes rebuild the point with the
// same function from the same depth, but another shader's compiler may round it differently
// (a few ulps of the position; the margin is a hundred times that).
float mark_margin(vec3 world) {
    return 1e-3 + 1e-5 * length(world) * frame.light_grid_origin.w;
}

// Mark cells c0..c1 (one row along x).
void mark_run(uint c0, uint c1) {
    for (uint word = c0 >> 5u; word <= c1 >> 5u; ++word) {
        uint first = max(c0, word << 5u) - (word << 5u);
        uint last = min(c1, (word << 5u) + 31u) - (word << 5u);
        uint bits = (0xffffffffu >> (31u - last)) & (0xffffffffu << first);
        // Neighbouring pixels mark the same cells: an atomic only where a bit is missing
        // (bits are only ever set, so a stale read costs at most a needless atomic).
        if ((grid_occupancy[word].x & bits) != bits) {
            atomicOr(grid_occupancy[word].x, bits);
        }
    }
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) {
        return;
    }
    float z = opaque_depth_at(p);
    if (z >= 1.0) {
        return;
    }
    vec3 world = world_from_depth(vec2(p) + 0.5, z);
    GridWalk w = grid_walk_wider(world, mark_margin(world));
    for (uint cz = w.lo.z; cz <= w.hi.z; ++cz) {
        for (uint cy = w.lo.y; cy <= w.hi.y; ++cy) {
            uint row = (cz * frame.light_grid_dims.y + cy) * frame.light_grid_dims.x;
            mark_run(row + w.lo.x, row + w.hi.x);
        }
    }
}
