// Marking the light grid's cells a point's walk visits (light_grid_mark.glsl from the opaque
// depth, light_grid_mark_layers.comp from the transparent layers' nodes). Needs common.glsl,
// `frame` and the marks (`grid_occupancy`, coherent).

#ifndef MANYLIGHTS_LIGHT_GRID_MARKING_GLSL
#define MANYLIGHTS_LIGHT_GRID_MARKING_GLSL

#include "common/world_from_depth.glsl"
#include "light_grid/light_grid_walk.glsl"

// Cells beyond the walk's reach a mark adds: the shading passes rebuild the point with the
// same function from the same depth, but another shader's compiler may round it differently
// (a few ulps of the position; the margin is a hundred times that).
float mark_margin(vec3 world) {
    return 1e-3 + 1e-5 * length(world) * frame.light_grid_origin.w;
}

// Set `bits` of the grid's marks' word `word`.
void mark_word(uint word, uint bits) {
    // Neighbouring work groups mark the same cells: an atomic only where a bit is missing
    // (bits are only ever set, so an outdated read costs at most a needless atomic).
    if ((grid_occupancy[word].x & bits) != bits) {
        atomicOr(grid_occupancy[word].x, bits);
    }
}

// The mask of bits first..last of a word (0 ≤ first ≤ last ≤ 31).
uint bits_between(uint first, uint last) {
    return (0xffffffffu >> (31u - last)) & (0xffffffffu << first);
}

// Mark cells c0..c1 (one row along x) in the grid's marks.
void mark_run(uint c0, uint c1) {
    for (uint word = c0 >> 5u; word <= c1 >> 5u; ++word) {
        mark_word(word, bits_between(max(c0, word << 5u) - (word << 5u), min(c1, (word << 5u) + 31u) - (word << 5u)));
    }
}

// Mark the cells of walk `w`'s box, row by row, in the grid's marks.
void mark_rows(GridWalk w) {
    for (uint cz = w.lo.z; cz <= w.hi.z; ++cz) {
        for (uint cy = w.lo.y; cy <= w.hi.y; ++cy) {
            uint row = (cz * frame.light_grid_dims.y + cy) * frame.light_grid_dims.x;
            mark_run(row + w.lo.x, row + w.hi.x);
        }
    }
}

// The walk a mark covers for a point at `world`: its cells and the margin beyond.
GridWalk mark_walk_of(vec3 world) {
    return grid_walk_wider(world, mark_margin(world));
}

// The walks a mark covers for every point in the box [lo, hi]: the walk's cells grow with
// the point, so the box's corners bound them.
GridWalk mark_walk_of_box(vec3 lo, vec3 hi) {
    float margin = mark_margin(max(abs(lo), abs(hi)));
    GridWalk w = grid_walk_wider(lo, margin);
    w.hi = grid_walk_wider(hi, margin).hi;
    return w;
}

// Mark every cell the walk of a point at `world` visits.
void mark_walk(vec3 world) {
    mark_rows(mark_walk_of(world));
}

#endif
