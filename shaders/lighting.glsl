// The light loop every shading path shares (forward and clustered fragment shaders, the
// deferred lighting subpass, the deferred-compute pass): one BRDF source, one summation order
// (ascending light index), so culling and deferring change no pixel.
//
// The includer includes scene_bindings.glsl (`frame`, `lights[]`, with CLUSTERED the lists)
// and textures.glsl.

#ifndef MANYLIGHTS_LIGHTING_GLSL
#define MANYLIGHTS_LIGHTING_GLSL

#include "seed_brdf.glsl"
#include "blinn_phong.glsl"
#include "cluster.glsl"

// One point light's contribution under the frame's shading model.
vec3 point_light(PointLight light, vec3 world, vec3 n, vec3 v, vec3 albedo, float roughness, float metallic) {
    if (frame.shading_model == SHADING_BLINN_PHONG) {
        return bp_point_light(light, world, n, v, albedo, mix(vec3(0.04), albedo, metallic), 1.0 - roughness);
    }
    return seed_point_light(light, world, n, v, albedo, roughness, metallic);
}

// Linear colour of a surface point: every light that reaches it plus what the model adds
// (seed: ambient; blinn-phong: ambient, sun, spot, reflection). `frag_xy` is the pixel
// centre (gl_FragCoord.xy), which picks the cluster.
vec3 shade_point(vec3 world, vec3 n, vec3 albedo, float roughness, float metallic, vec2 frag_xy) {
    vec3 v = normalize(frame.camera_pos.xyz - world);
    vec3 lo = vec3(0.0);
#ifdef CLUSTERED
    float depth = -(frame.view * vec4(world, 1.0)).z;
    ClusterRange range = cluster_ranges[cluster_of(frame, frag_xy, depth)];
    for (uint k = 0u; k < range.count; ++k) {
        uint i = light_indices[range.offset + k];
        lo += point_light(lights[i], world, n, v, albedo, roughness, metallic);
    }
#else
    for (uint i = 0u; i < frame.light_count; ++i) {
        lo += point_light(lights[i], world, n, v, albedo, roughness, metallic);
    }
#endif
    if (frame.shading_model == SHADING_BLINN_PHONG) {
        return bp_scene_lights(world, n, v, albedo, mix(vec3(0.04), albedo, metallic), 1.0 - roughness) + lo;
    }
    return albedo * frame.ambient + lo;
}

// Lights in the fragment's cluster (the cluster-heat debug view).
#ifdef CLUSTERED
uint cluster_light_count(vec3 world, vec2 frag_xy) {
    float depth = -(frame.view * vec4(world, 1.0)).z;
    return cluster_ranges[cluster_of(frame, frag_xy, depth)].count;
}
#endif

// World position of the pixel centre `frag_xy` at depth-buffer value `z` (deferred paths).
vec3 world_from_depth(vec2 frag_xy, float z) {
    vec2 ndc = frag_xy / vec2(frame.viewport.xy) * 2.0 - 1.0;
    vec4 w = frame.inv_view_proj * vec4(ndc, z, 1.0);
    return w.xyz / w.w;
}

#endif
