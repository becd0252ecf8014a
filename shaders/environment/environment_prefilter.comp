#version 450
#extension GL_GOOGLE_include_directive : require
// One level of the specular cube: each texel the environment's radiance weighted by a GGX
// lobe about its direction (n = v = r, the split sum's assumption), roughness growing
// linearly with the level. GGX importance sampling with Hammersley points, each sample read
// from the source cube's mip whose texel covers the sample's share of the lobe (Karis 2013,
// "filtered importance sampling"), so a few hundred samples give a smooth lobe.
#include "common/common.glsl"
#include "common/seed_brdf.glsl"
#include "environment/environment_maps.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(set = 0, binding = 0) uniform samplerCube source;
layout(set = 0, binding = 1, rgba16f) uniform writeonly image2DArray specular_level;

layout(push_constant) uniform Prefilter {
    float roughness;
    uint samples;
} prefilter;

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    ivec2 face_size = imageSize(specular_level).xy;
    if (any(greaterThanEqual(p.xy, face_size))) {
        return;
    }
    vec3 n = normalize(cube_direction(p.z, (vec2(p.xy) + 0.5) / vec2(face_size)));
    // Through opaque_uniform: lavapipe would compile the shader anew for every level's push.
    float roughness = opaque_uniform(prefilter.roughness);
    if (roughness == 0.0) {
        imageStore(specular_level, p, vec4(textureLod(source, n, 0.0).rgb, 1.0));
        return;
    }
    float source_size = float(textureSize(source, 0).x);
    float texel_solid_angle = 4.0 * ENV_PI / (6.0 * source_size * source_size);
    uint samples = opaque_uniform(prefilter.samples);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (uint i = 0u; i < samples; ++i) {
        vec3 h = about_normal(ggx_half_vector(hammersley(i, samples), roughness), n);
        vec3 l = 2.0 * dot(n, h) * h - n;
        float n_dot_l = dot(n, l);
        if (n_dot_l > 0.0) {
            // pdf(l) = D(h)·(n·h) / (4·(v·h)) = D(h) / 4 with v = n.
            float pdf = d_ggx(max(dot(n, h), 0.0), roughness) / 4.0;
            float sample_solid_angle = 1.0 / (float(samples) * pdf + 1e-6);
            float lod = max(0.5 * log2(sample_solid_angle / texel_solid_angle), 0.0);
            sum += textureLod(source, l, lod).rgb * n_dot_l;
            weight += n_dot_l;
        }
    }
    imageStore(specular_level, p, vec4(sum / max(weight, 1e-6), 1.0));
}
