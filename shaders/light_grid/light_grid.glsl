// The light grid's walk (docs/DESIGN.md#the-light-grid): the lights a surface point tests.
// Keep in sync with crates/ml-cpu/src/light_grid.rs (LightGridShape::rows_near).
//
// The lists, as the build leaves them: the cells' lights one run after another in cell order
// (x fastest), then the wide lights; `grid_cell_ends[c]` is where cell c's run ends relative
// to its block of GRID_BLOCK cells, `grid_blocks[b].x` where block b starts. A row of cells
// along x is then one contiguous run of the list.

#ifndef MANYLIGHTS_LIGHT_GRID_GLSL
#define MANYLIGHTS_LIGHT_GRID_GLSL

const uint GRID_BLOCK = 1024u;
// Relative margin on the reach (light_grid.rs GRID_MARGIN).
const float GRID_MARGIN = 1e-4;

// The grid's light j as it is this frame: at rest, moved by the frame's offset.
PointLight grid_light(uint j) {
    PointLight l = lights[j];
    l.position_radius.xyz += frame.light_animation.xyz;
    return l;
}

// Where list c (a cell, or frame.light_grid_dims.w: the wide lights) ends and starts.
uint grid_end(uint c) {
    return grid_blocks[c / GRID_BLOCK].x + grid_cell_ends[c];
}

uint grid_start(uint c) {
    return c == 0u ? 0u : grid_end(c - 1u);
}

// A point's walk: its place in cell units, the reach in cell units and the cells it spans.
struct GridWalk {
    vec3 g;
    float r;
    uvec3 lo;
    uvec3 hi;
};

GridWalk grid_walk(vec3 world) {
    GridWalk w;
    w.g = (world - frame.light_grid_origin.xyz) * frame.light_grid_origin.w;
    w.r = frame.light_grid_reach.x * frame.light_grid_origin.w * (1.0 + GRID_MARGIN);
    vec3 top = vec3(frame.light_grid_dims.xyz - 1u);
    w.lo = uvec3(clamp(floor(w.g - w.r), vec3(0.0), top));
    w.hi = uvec3(clamp(floor(w.g + w.r), vec3(0.0), top));
    return w;
}

// Distance in cells from g to the slab of cell c along an axis of n cells, border cells
// reaching to infinity (they hold the lights beyond the grid).
float grid_slab_distance(float g, uint c, uint n) {
    float below = c == 0u ? 0.0 : float(c) - g;
    float above = c + 1u == n ? 0.0 : g - float(c + 1u);
    return max(max(below, above), 0.0);
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
    return uvec2(grid_start(row + x0), grid_end(row + x1));
}

// Run BODY for each light `i_` (in the grid's order: grid_light(i_)) that a point at `world`
// tests: the wide lights, then the rows of cells within reach.
#define GRID_FOR_LIGHTS(BODY)                                                   \
    {                                                                           \
        if (frame.light_grid_reach.y > 0.0) {                                   \
            uint wide_ = frame.light_grid_dims.w;                               \
            for (uint k_ = grid_start(wide_); k_ < grid_end(wide_); ++k_) {     \
                uint i_ = grid_lights[k_];                                      \
                BODY                                                            \
            }                                                                   \
        }                                                                       \
        GridWalk w_ = grid_walk(world);                                         \
        for (uint z_ = w_.lo.z; z_ <= w_.hi.z; ++z_) {                          \
            for (uint y_ = w_.lo.y; y_ <= w_.hi.y; ++y_) {                      \
                uvec2 run_ = grid_row(w_, y_, z_);                              \
                for (uint k_ = run_.x; k_ < run_.y; ++k_) {                     \
                    uint i_ = grid_lights[k_];                                  \
                    BODY                                                        \
                }                                                               \
            }                                                                   \
        }                                                                       \
    }

#endif
