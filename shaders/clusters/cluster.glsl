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

// Heat-map colour for t in 0..1: black → blue → cyan → green → yellow → red.
vec3 heat(float t) {
    const vec3 stops[6] = vec3[6](vec3(0.0), vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 1.0),
                                  vec3(0.0, 1.0, 0.0), vec3(1.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0));
    float x = clamp(t, 0.0, 1.0) * 5.0;
    int i = min(int(x), 4);
    return mix(stops[i], stops[i + 1], x - float(i));
}

#endif
