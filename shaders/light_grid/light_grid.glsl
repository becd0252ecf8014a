// The light grid's walk (docs/DESIGN.md#the-light-grid): the lights a surface point tests.
// Keep in sync with crates/ml-cpu/src/light_grid.rs (LightGridShape::rows_near).
//
// The lists, as the build leaves them: list 0 holds the wide lights, then one list per marked
// cell (a cell within reach of a surface point of the frame, light_grid_mark.glsl; every cell
// where nothing marks) in cell order (x fastest), each light a copy moved to where it is this
// frame. `grid_list_ends[l]` is where list l ends; `grid_occupancy[c / 32]` has the marked bits
// of 32 cells and the list of its first marked cell. The cells a point walks are all marked,
// so a row of them along x is one contiguous run of the lists.

#ifndef MANYLIGHTS_LIGHT_GRID_GLSL
#define MANYLIGHTS_LIGHT_GRID_GLSL

#include "light_grid/light_grid_walk.glsl"

// The list of marked cell c (of an unmarked cell: the next marked cell's).
uint grid_list(uint c) {
    uvec2 o = grid_occupancy[c >> 5u];
    return o.y + bitCount(o.x & ((1u << (c & 31u)) - 1u));
}

// Where list l ends and starts.
uint grid_end(uint l) {
    return grid_list_ends[l];
}

uint grid_start(uint l) {
    return l == 0u ? 0u : grid_list_ends[l - 1u];
}

// The run of the list that row (y, z) gives the walk (empty where the row is out of reach).
uvec2 grid_row(GridWalk w, uint y, uint z) {
    float dy = grid_slab_distance(w.g.y, y, frame.light_grid_dims.y);
    float dz = grid_slab_distance(w.g.z, z, frame.light_grid_dims.z);
    float h2 = w.r * w.r - dy * dy - dz * dz;
    if (h2 < 0.0) {
        return uvec2(0u);
    }
    float h = sqrt(h2);
    float top = float(frame.light_grid_dims.x - 1u);
    uint row = (z * frame.light_grid_dims.y + y) * frame.light_grid_dims.x;
    uint x0 = uint(clamp(floor(w.g.x - h), 0.0, top));
    uint x1 = uint(clamp(floor(w.g.x + h), 0.0, top));
    return uvec2(grid_start(grid_list(row + x0)), grid_end(grid_list(row + x1)));
}

// Run BODY for each place `k_` of the lists (the light grid_lights[k_], its scene index
// grid_scene_index[k_]) that a point at `world` tests: the wide lights, then the rows of
// cells within reach.
#define GRID_FOR_LIGHTS(BODY)                                                   \
    {                                                                           \
        uint wide_end_ = grid_end(0u);                                          \
        for (uint k_ = 0u; k_ < wide_end_; ++k_) {                              \
            BODY                                                                \
        }                                                                       \
        GridWalk w_ = grid_walk(world);                                         \
        for (uint z_ = w_.lo.z; z_ <= w_.hi.z; ++z_) {                          \
            for (uint y_ = w_.lo.y; y_ <= w_.hi.y; ++y_) {                      \
                uvec2 run_ = grid_row(w_, y_, z_);                              \
                for (uint k_ = run_.x; k_ < run_.y; ++k_) {                     \
                    BODY                                                        \
                }                                                               \
            }                                                                   \
        }                                                                       \
    }

#endif
