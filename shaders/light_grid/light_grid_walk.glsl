// The light grid's cells near a point (docs/DESIGN.md#the-light-grid): the walk's geometry,
// which the shading passes (light_grid.glsl) and the marks (light_grid_mark.glsl) share.
// Keep in sync with crates/ml-cpu/src/light_grid.rs (LightGridShape::rows_near). Needs
// `frame` (FrameBlock).

#ifndef MANYLIGHTS_LIGHT_GRID_WALK_GLSL
#define MANYLIGHTS_LIGHT_GRID_WALK_GLSL

// Relative margin on the reach (light_grid.rs GRID_MARGIN).
const float GRID_MARGIN = 1e-4;

// A point's walk: its place in cell units, the reach in cell units and the cells it spans.
struct GridWalk {
    vec3 g;
    float r;
    uvec3 lo;
    uvec3 hi;
};

// The walk of a point at `world` over the cells within `extra` cells beyond the reach.
GridWalk grid_walk_wider(vec3 world, float extra) {
    GridWalk w;
    w.g = (world - frame.light_grid_origin.xyz) * frame.light_grid_origin.w;
    w.r = frame.light_grid_reach.x * frame.light_grid_origin.w * (1.0 + GRID_MARGIN);
    vec3 top = vec3(frame.light_grid_dims.xyz - 1u);
    w.lo = uvec3(clamp(floor(w.g - (w.r + extra)), vec3(0.0), top));
    w.hi = uvec3(clamp(floor(w.g + (w.r + extra)), vec3(0.0), top));
    return w;
}

GridWalk grid_walk(vec3 world) {
    return grid_walk_wider(world, 0.0);
}

// Distance in cells from g to the slab of cell c along an axis of n cells, border cells
// reaching to infinity (they hold the lights beyond the grid).
float grid_slab_distance(float g, uint c, uint n) {
    float below = c == 0u ? 0.0 : float(c) - g;
    float above = c + 1u == n ? 0.0 : g - float(c + 1u);
    return max(max(below, above), 0.0);
}

// The list of cell c, marked, from its word of marks `o` (per 32 cells their bits and the list
// of the first marked one): its word's first marked cell's, plus the marked cells before it in
// the word.
uint grid_word_list(uvec2 o, uint c) {
    return o.y + bitCount(o.x & ((1u << (c & 31u)) - 1u));
}

#endif
