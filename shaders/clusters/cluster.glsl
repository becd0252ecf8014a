// Which cluster a fragment is in. Keep in sync with crates/ml-cpu/src/cluster/grid.rs: tiles
// in integer arithmetic from the pixel, slices as floor(log(depth) * scale + bias) with the
// scale and bias the CPU computed, so both sides evaluate the same expression.

#ifndef MANYLIGHTS_CLUSTER_GLSL
#define MANYLIGHTS_CLUSTER_GLSL

uint cluster_slice(FrameUniforms f, float depth) {
    float s = floor(log(depth) * f.cluster_slices.x + f.cluster_slices.y);
    return uint(clamp(s, 0.0, float(f.cluster_dims.z - 1u)));
}

uint cluster_of(FrameUniforms f, vec2 frag_coord, float depth) {
    uvec2 px = uvec2(frag_coord);
    uint x = px.x * f.cluster_dims.x / f.viewport.x;
    uint y = px.y * f.cluster_dims.y / f.viewport.y;
    return (cluster_slice(f, depth) * f.cluster_dims.y + y) * f.cluster_dims.x + x;
}

// Relative slack of every cluster box (see grid.rs SLACK).
const float CLUSTER_SLACK = 1e-4;

// Depth where slice k starts: near · (far/near)^(k/Z).
float cluster_slice_start(FrameUniforms f, uint k) {
    return f.cluster_frustum.x * pow(f.cluster_frustum.y / f.cluster_frustum.x, float(k) / float(f.cluster_dims.z));
}

// Clip w at view depth `depth`: the depth for a perspective camera, 1 for an orthographic
// one (camera_pos.w says which; grid.rs w_of_depth, inv_w).
float cluster_w(FrameUniforms f, float depth) {
    return f.camera_pos.w * depth + (1.0 - f.camera_pos.w);
}

float cluster_inv_w(FrameUniforms f, float depth) {
    return 1.0 / cluster_w(f, depth);
}

uint cluster_tile(uint pixel, uint tiles, uint size) {
    return pixel * tiles / size;
}

// Pixels whose centres may lie in NDC [lo, hi] (one pixel of margin), clamped to the image;
// false when off screen. Keep in sync with grid.rs pixel_span.
bool cluster_pixel_span(float lo, float hi, uint size, out uvec2 span) {
    float a = (lo + 1.0) * 0.5 * float(size) - 1.0;
    float b = (hi + 1.0) * 0.5 * float(size) + 1.0;
    if (b < 0.0 || a >= float(size)) {
        return false;
    }
    span = uvec2(uint(max(a, 0.0)), uint(min(b, float(size) - 1.0)));
    return true;
}

// Tiles under the view-space box v ∈ [va, vb], 1/w ∈ inv (x: 1/w0, y: 1/w1), along an axis
// with projection scale `scale`. Keep in sync with grid.rs tile_span_x / projected_span.
bool cluster_tile_span(float scale, float va, float vb, vec2 inv, uint size, uint tiles, out uvec2 span) {
    vec4 c = vec4(va * inv.x, va * inv.y, vb * inv.x, vb * inv.y) * scale;
    float lo = min(min(c.x, c.y), min(c.z, c.w));
    float hi = max(max(c.x, c.y), max(c.z, c.w));
    uvec2 px;
    if (!cluster_pixel_span(lo, hi, size, px)) {
        return false;
    }
    span = uvec2(cluster_tile(px.x, tiles, size), cluster_tile(px.y, tiles, size));
    return true;
}

// Heat-map colour for t in 0..1: black → blue → cyan → green → yellow → red.
vec3 heat(float t) {
    const vec3 stops[6] = vec3[6](vec3(0.0), vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 1.0),
                                  vec3(0.0, 1.0, 0.0), vec3(1.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0));
    float x = clamp(t, 0.0, 1.0) * 5.0;
    int i = min(int(x), 4);
    return mix(stops[i], stops[i + 1], x - float(i));
}

#endif
