#version 450
#extension GL_GOOGLE_include_directive : require
// clustered-gpu, run when projection or image size change: every cluster's view-space box.
// Keep in sync with ClusterGrid::compute_bounds (grid.rs).
#include "common/common.glsl"
#include "clusters/cluster.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 3) writeonly buffer BoundsBuffer { ClusterBounds bounds[]; };

// Pixel-centre span of tile t: pixels p with p·tiles/size = t.
vec2 tile_centres(uint t, uint tiles, uint size) {
    uint first = (t * size + tiles - 1u) / tiles;
    uint last = ((t + 1u) * size + tiles - 1u) / tiles - 1u;
    return vec2(float(first) + 0.5, float(last) + 0.5);
}

void main() {
    uvec3 d = frame.cluster_dims.xyz;
    uint index = gl_GlobalInvocationID.x;
    if (index >= d.x * d.y * d.z) {
        return;
    }
    uint x = index % d.x;
    uint y = (index / d.x) % d.y;
    uint z = index / (d.x * d.y);
    float z0 = cluster_slice_start(frame, z) * (1.0 - CLUSTER_SLACK);
    float z1 = cluster_slice_start(frame, z + 1u) * (1.0 + CLUSTER_SLACK);
    vec2 xs = tile_centres(x, d.x, frame.viewport.x);
    vec2 ys = tile_centres(y, d.y, frame.viewport.y);
    vec3 lo = vec3(3.4e38);
    vec3 hi = vec3(-3.4e38);
    for (int corner = 0; corner < 4; ++corner) {
        float px = (corner & 1) == 0 ? xs.x : xs.y;
        float py = (corner & 2) == 0 ? ys.x : ys.y;
        vec2 ndc = vec2(px / float(frame.viewport.x), py / float(frame.viewport.y)) * 2.0 - 1.0;
        // At view depth d the pixel is at ndc · w / p (w: clip w, cluster_w).
        vec2 dir = vec2(ndc.x / frame.cluster_frustum.z, ndc.y / frame.cluster_frustum.w);
        vec3 p0 = vec3(dir * cluster_w(frame, z0), -z0);
        vec3 p1 = vec3(dir * cluster_w(frame, z1), -z1);
        lo = min(lo, min(p0, p1));
        hi = max(hi, max(p0, p1));
    }
    vec3 pad = max(hi - lo, vec3(z1 - z0)) * CLUSTER_SLACK;
    bounds[index] = ClusterBounds(vec4(lo - pad, 0.0), vec4(hi + pad, 0.0));
}
