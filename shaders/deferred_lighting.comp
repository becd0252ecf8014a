#version 450
#extension GL_GOOGLE_include_directive : require
// deferred-compute: the clustered lighting of forward_frag.glsl as a compute shader over the
// G-buffer (on H100/H200 compute runs on all SMs, fragment shading on 4 of 132). Same BRDF,
// same cluster lookup, same light order as the forward path; position rebuilt from depth.
#include "common.glsl"
#include "seed_brdf.glsl"
#include "cluster.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 1) readonly buffer LightBuffer { PointLight lights[]; };
layout(std430, set = 0, binding = 2) readonly buffer ClusterRangeBuffer { ClusterRange cluster_ranges[]; };
layout(std430, set = 0, binding = 3) readonly buffer LightIndexBuffer { uint light_indices[]; };
layout(std430, set = 0, binding = 4) readonly buffer ObjectBuffer { ObjectPush objects[]; };
layout(set = 0, binding = 5) uniform sampler2D depth_image;
layout(set = 0, binding = 6) uniform sampler2D normal_image;
layout(set = 0, binding = 7) uniform usampler2D object_image;
layout(set = 0, binding = 8, rgba8) uniform writeonly image2D out_image;

// Keep in sync with raster.rs CLEAR_COLOR.
const vec4 CLEAR_COLOR = vec4(0.02, 0.02, 0.02, 1.0);

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) {
        return;
    }
    float z = texelFetch(depth_image, p, 0).r;
    if (z >= 1.0) {
        imageStore(out_image, p, CLEAR_COLOR);
        return;
    }
    vec2 ndc = (vec2(p) + 0.5) / vec2(frame.viewport.xy) * 2.0 - 1.0;
    vec4 w = frame.inv_view_proj * vec4(ndc, z, 1.0);
    vec3 world = w.xyz / w.w;
    vec3 n = oct_decode(texelFetch(normal_image, p, 0).xy);
    ObjectPush object = objects[texelFetch(object_image, p, 0).r];
    vec3 v = normalize(frame.camera_pos.xyz - world);
    vec3 albedo = object.albedo_roughness.rgb;
    float roughness = object.albedo_roughness.a;
    float metallic = object.material.x;

    float depth = -(frame.view * vec4(world, 1.0)).z;
    ClusterRange range = cluster_ranges[cluster_of(frame, vec2(p) + 0.5, depth)];
    vec3 lo = vec3(0.0);
    for (uint k = 0u; k < range.count; ++k) {
        uint i = light_indices[range.offset + k];
        lo += seed_point_light(lights[i], world, n, v, albedo, roughness, metallic);
    }
    vec3 color = albedo * frame.ambient + lo;
    imageStore(out_image, p, vec4(pow(color, vec3(1.0 / 2.2)), 1.0));
}
