// Fragment shader of the forward techniques. `forward.frag` loops over every light;
// `clustered.frag` defines CLUSTERED and loops over its cluster's lights only. Everything
// else — inputs, BRDF, summation order (ascending light index) — is shared, so the two give
// the same image when culling is correct.

#include "common.glsl"
#include "seed_brdf.glsl"
#include "cluster.glsl"

layout(location = 0) in vec3 in_world_pos;
layout(location = 1) in vec3 in_normal;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 1) readonly buffer LightBuffer { PointLight lights[]; };
#ifdef CLUSTERED
layout(std430, set = 0, binding = 2) readonly buffer ClusterRangeBuffer { ClusterRange cluster_ranges[]; };
layout(std430, set = 0, binding = 3) readonly buffer LightIndexBuffer { uint light_indices[]; };
#endif
layout(push_constant) uniform PushBlock { ObjectPush object; };

layout(location = 0) out vec4 out_color;

void main() {
    vec3 n = normalize(in_normal);
    vec3 v = normalize(frame.camera_pos.xyz - in_world_pos);
    vec3 albedo = object.albedo_roughness.rgb;
    float roughness = object.albedo_roughness.a;
    float metallic = object.material.x;

    vec3 lo = vec3(0.0);
#ifdef CLUSTERED
    float depth = -(frame.view * vec4(in_world_pos, 1.0)).z;
    ClusterRange range = cluster_ranges[cluster_of(frame, gl_FragCoord.xy, depth)];
    if (frame.cluster_dims.w == DEBUG_VIEW_CLUSTER_HEAT) {
        // Lights per cluster on a log scale up to cluster_slices.z.
        float t = log2(1.0 + float(range.count)) / log2(1.0 + frame.cluster_slices.z);
        out_color = vec4(heat(t), 1.0);
        return;
    }
    for (uint k = 0u; k < range.count; ++k) {
        uint i = light_indices[range.offset + k];
        lo += seed_point_light(lights[i], in_world_pos, n, v, albedo, roughness, metallic);
    }
#else
    for (uint i = 0u; i < frame.light_count; ++i) {
        lo += seed_point_light(lights[i], in_world_pos, n, v, albedo, roughness, metallic);
    }
#endif
    vec3 color = albedo * frame.ambient + lo;
    // The target is UNORM: the seed writes gamma-encoded values itself.
    out_color = vec4(pow(color, vec3(1.0 / 2.2)), 1.0);
}
