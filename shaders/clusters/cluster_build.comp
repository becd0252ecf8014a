#version 450
#extension GL_GOOGLE_include_directive : require
// clustered-gpu, every frame, one invocation per light. Run twice: COUNT (animates the light,
// writes it for shading, counts it into every cluster it touches) and FILL (after the prefix
// sum: writes its index into those clusters' lists). The clusters a light touches are found as
// on the CPU (assign.rs light_clusters; keep in sync): per depth slice, the sphere's cross-
// section in that slab projected to a tile rectangle, then sphere vs each cluster's box.
#include "common/common.glsl"
#include "clusters/cluster.glsl"

layout(local_size_x = 128) in;
layout(constant_id = 0) const bool FILL = false;
// Invocations per light. Few lights are big and many small: with few lights each gets up to
// 64 invocations that share its candidate tiles, so the GPU stays busy; with many, one.
layout(constant_id = 1) const uint LANES = 1u;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 1) readonly buffer RestLightBuffer { PointLight rest_lights[]; };
layout(std430, set = 0, binding = 2) writeonly buffer LightBuffer { PointLight lights[]; };
layout(std430, set = 0, binding = 3) readonly buffer BoundsBuffer { ClusterBounds bounds[]; };
// COUNT: per-cluster counts; after the scan: per-cluster write cursors.
layout(std430, set = 0, binding = 4) buffer CounterBuffer { uint counters[]; };
layout(std430, set = 0, binding = 6) writeonly buffer LightIndexBuffer { uint light_indices[]; };

void touch(uint cluster, uint light) {
    if (FILL) {
        uint slot = atomicAdd(counters[cluster], 1u);
        if (slot < frame.cluster_build.x) {
            light_indices[slot] = light;
        }
    } else {
        atomicAdd(counters[cluster], 1u);
    }
}

void main() {
    uint i = gl_GlobalInvocationID.x / LANES;
    uint lane = gl_GlobalInvocationID.x % LANES;
    if (i >= frame.light_count) {
        return;
    }
    PointLight light = rest_lights[i];
    light.position_radius.xyz += frame.light_animation.xyz;
    // (Written as if/else: reflection tools cannot fold a specialization-constant `!`.)
    if (FILL) {
    } else if (lane == 0u) {
        lights[i] = light;
    }
    float r = light.position_radius.w;
    vec3 c = (frame.view * vec4(light.position_radius.xyz, 1.0)).xyz;
    float depth = -c.z;
    float dmin = depth - r;
    float dmax = depth + r;
    float near = frame.cluster_frustum.x;
    float far = frame.cluster_frustum.y;
    if (dmax < near || dmin > far) {
        return;
    }
    // Wholly outside a side plane of the frustum (grid.rs outside_side_planes)?
    float p00 = frame.cluster_frustum.z;
    float p11 = abs(frame.cluster_frustum.w);
    float a = frame.camera_pos.w;
    float w = cluster_w(frame, depth);
    if (p00 * abs(c.x) - w > r * sqrt(p00 * p00 + a * a) || p11 * abs(c.y) - w > r * sqrt(p11 * p11 + a * a)) {
        return;
    }
    uvec3 d = frame.cluster_dims.xyz;
    uvec2 size = frame.viewport.xy;
    float d0 = max(dmin, near);
    vec2 inv = vec2(cluster_inv_w(frame, d0), cluster_inv_w(frame, dmax));
    uvec2 xs;
    uvec2 ys;
    if (!cluster_tile_span(frame.cluster_frustum.z, c.x - r, c.x + r, inv, size.x, d.x, xs)
        || !cluster_tile_span(frame.cluster_frustum.w, c.y - r, c.y + r, inv, size.y, d.y, ys)) {
        return;
    }
    uint k0 = cluster_slice(frame, d0);
    uint k1 = cluster_slice(frame, min(dmax, far));
    float r2 = r * r;
    for (uint z = k0; z <= k1; ++z) {
        float s0 = max(max(cluster_slice_start(frame, z) * (1.0 - CLUSTER_SLACK), dmin), near);
        float s1 = min(cluster_slice_start(frame, z + 1u) * (1.0 + CLUSTER_SLACK), dmax);
        if (s0 > s1) {
            continue;
        }
        // A light within one slice keeps its whole rectangle (as assign.rs does).
        if (k0 != k1) {
            float closest = clamp(depth, s0, s1);
            float rr = sqrt(max(r2 - (closest - depth) * (closest - depth), 0.0));
            vec2 slab = vec2(cluster_inv_w(frame, s0), cluster_inv_w(frame, s1));
            if (!cluster_tile_span(frame.cluster_frustum.z, c.x - rr, c.x + rr, slab, size.x, d.x, xs)
                || !cluster_tile_span(frame.cluster_frustum.w, c.y - rr, c.y + rr, slab, size.y, d.y, ys)) {
                continue;
            }
        }
        uint w = xs.y - xs.x + 1u;
        uint cells = w * (ys.y - ys.x + 1u);
        for (uint k = lane; k < cells; k += LANES) {
            uint index = (z * d.y + ys.x + k / w) * d.x + xs.x + k % w;
            ClusterBounds b = bounds[index];
            vec3 e = max(max(b.min_corner.xyz - c, c - b.max_corner.xyz), vec3(0.0));
            if (dot(e, e) <= r2) {
                touch(index, i);
            }
        }
    }
}
