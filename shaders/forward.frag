#version 450
#extension GL_GOOGLE_include_directive : require
// Technique `forward`: brute force, every fragment loops over every light.
#include "common.glsl"
#include "seed_brdf.glsl"

layout(location = 0) in vec3 in_world_pos;
layout(location = 1) in vec3 in_normal;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 1) readonly buffer LightBuffer { PointLight lights[]; };
layout(push_constant) uniform PushBlock { ObjectPush object; };

layout(location = 0) out vec4 out_color;

void main() {
    vec3 n = normalize(in_normal);
    vec3 v = normalize(frame.camera_pos.xyz - in_world_pos);
    vec3 albedo = object.albedo_roughness.rgb;
    float roughness = object.albedo_roughness.a;
    float metallic = object.material.x;

    vec3 lo = vec3(0.0);
    for (uint i = 0u; i < frame.light_count; ++i) {
        lo += seed_point_light(lights[i], in_world_pos, n, v, albedo, roughness, metallic);
    }
    vec3 color = albedo * frame.ambient + lo;
    // The target is UNORM: the seed writes gamma-encoded values itself.
    out_color = vec4(pow(color, vec3(1.0 / 2.2)), 1.0);
}
