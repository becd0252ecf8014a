// The light grid's walk (docs/DESIGN.md#the-light-grid): the lights a surface point tests.
// Keep in sync with crates/ml-cpu/src/light_grid.rs (LightGridShape::rows_near).
//
// The lists, as the build leaves them: the wide lights' (list 0), then a list per marked cell
// (a cell some surface point of the frame walks, light_grid_mark.glsl; every cell where
// nothing marks), cell after cell in cell order (x fastest), each light moved to where it is
// this frame, its position and radius apart from its colour (a point reads the colour only of
// the lights that reach it). `grid_lists[l]` is where list l ends and list l + 1 starts;
// a marked cell's list is its rank among the marked cells, from the marks' words
// (`grid_occupancy`: per 32 cells their bits and the list of the first marked one). The
// cells a point walks are all marked, so a row of them along x is one contiguous run of the
// lists, from the start of its first cell's list to the end of its last's. Only the small
// per-word table and the lists are read, never a table of every cell.

#ifndef MANYLIGHTS_LIGHT_GRID_GLSL
#define MANYLIGHTS_LIGHT_GRID_GLSL

#include "light_grid/light_grid_walk.glsl"

// The list of marked cell c.
uint grid_list(uint c) {
    return grid_word_list(grid_occupancy[c >> 5u], c);
}

// The run of the lists that row (y, z) gives the walk (empty where the row is out of reach).
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
    // Lists are numbered from 1 after the wide lights' list 0.
    return uvec2(grid_lists[grid_list(row + x0) - 1u], grid_lists[grid_list(row + x1)]);
}

// Run BODY for each place `k_` of the lists (the light's position and radius
// grid_light_positions[k_], its colour grid_light_colors[k_], its scene index
// grid_scene_index[k_]) that a point at `world` tests: the wide lights, then the rows of
// cells within reach (z outer, y inner). One loop over runs of the lists, the wide lights'
// the first, so that BODY — a light with its shadow code — is written once: lavapipe inlines
// every copy before it folds the constants, and each costs time to make the pipeline.
#define GRID_FOR_LIGHTS(BODY)                                                   \
    {                                                                           \
        GridWalk w_ = grid_walk(world);                                         \
        uint k_ = 0u, end_ = grid_lists[0];                                     \
        uint y_ = w_.lo.y, z_ = w_.lo.z;                                        \
        bool rows_ = w_.lo.y <= w_.hi.y && w_.lo.z <= w_.hi.z;                  \
        for (;;) {                                                              \
            for (; k_ < end_; ++k_) {                                           \
                BODY                                                            \
            }                                                                   \
            if (!rows_) {                                                       \
                break;                                                          \
            }                                                                   \
            uvec2 run_ = grid_row(w_, y_, z_);                                  \
            k_ = run_.x;                                                        \
            end_ = run_.y;                                                      \
            if (y_ < w_.hi.y) {                                                 \
                ++y_;                                                           \
            } else if (z_ < w_.hi.z) {                                          \
                y_ = w_.lo.y;                                                   \
                ++z_;                                                           \
            } else {                                                            \
                rows_ = false;                                                  \
            }                                                                   \
        }                                                                       \
    }

#endif
