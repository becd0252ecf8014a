// The light grid's walk (docs/DESIGN.md#the-light-grid): the lights a surface point tests.
// Keep in sync with crates/ml-cpu/src/light_grid.rs (LightGridShape::rows_near).
//
// The lists, as the build leaves them: the wide lights first, then the lights of each marked
// cell (a cell some surface point of the frame walks, light_grid_mark.glsl; every cell where
// nothing marks), cell after cell in cell order (x fastest), each light moved to where it is
// this frame, its position and radius apart from its colour (a point reads the colour only of
// the lights that reach it). `grid_cell_ranges[c]` is where marked cell c's lights start and
// end (other cells' entries are stale or never written: no point walks them),
// `grid_cell_ranges[cells]` the wide lights'. The cells a point walks are all marked, so a
// row of them along x is one contiguous run of the lists.

#ifndef MANYLIGHTS_LIGHT_GRID_GLSL
#define MANYLIGHTS_LIGHT_GRID_GLSL

#include "light_grid/light_grid_walk.glsl"

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
    return uvec2(grid_cell_ranges[row + x0].x, grid_cell_ranges[row + x1].y);
}

// Run BODY for each place `k_` of the lists (the light's position and radius
// grid_light_positions[k_], its colour grid_light_colors[k_], its scene index
// grid_scene_index[k_]) that a point at `world` tests: the wide lights, then the rows of
// cells within reach.
#define GRID_FOR_LIGHTS(BODY)                                                   \
    {                                                                           \
        uvec2 wide_ = grid_cell_ranges[frame.light_grid_dims.w];                \
        for (uint k_ = wide_.x; k_ < wide_.y; ++k_) {                           \
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
