#version 450
#extension GL_GOOGLE_include_directive : require
// The split sum's second factor: the BRDF's integral over the hemisphere as F₀·A + B per
// (n·v, roughness), texel centres at both ends of each axis (GGX importance sampling with
// Hammersley points; Smith–Schlick visibility with k = α/2). ml_cpu::environment::brdf_integral
// is the same sum. Third channel: what the Fresnel term takes from the diffuse layer under
// light from every direction (diffuse_fresnel_weight), a function of n·v alone.
#include "environment/environment_maps.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(set = 0, binding = 0, rgba16f) uniform writeonly image2D brdf_table;

const uint SAMPLES = 512u;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(brdf_table);
    if (any(greaterThanEqual(p, size))) {
        return;
    }
    vec2 at = vec2(p) / vec2(size - 1);
    float n_dot_v = max(at.x, 1e-4);
    float roughness = at.y;
    vec3 v = vec3(sqrt(1.0 - n_dot_v * n_dot_v), 0.0, n_dot_v);
    float k = roughness * roughness / 2.0;
    float a = 0.0, b = 0.0;
    for (uint i = 0u; i < SAMPLES; ++i) {
        vec3 h = ggx_half_vector(hammersley(i, SAMPLES), roughness);
        vec3 l = 2.0 * dot(v, h) * h - v;
        float n_dot_l = l.z, n_dot_h = max(h.z, 0.0), v_dot_h = max(dot(v, h), 0.0);
        if (n_dot_l > 0.0) {
            float g = (n_dot_l / (n_dot_l * (1.0 - k) + k)) * (n_dot_v / (n_dot_v * (1.0 - k) + k));
            float visibility = g * v_dot_h / (n_dot_h * n_dot_v);
            float fc = pow(1.0 - v_dot_h, 5.0);
            a += (1.0 - fc) * visibility;
            b += fc * visibility;
        }
    }
    // Schlick's weight (1 − v·h)⁵ of cosine-distributed light directions, averaged: glTF's
    // material weights its diffuse layer by 1 − F(v·h) for each (ml_cpu diffuse_fresnel_weight).
    float c = 0.0;
    for (uint i = 0u; i < SAMPLES; ++i) {
        vec2 xi = hammersley(i, SAMPLES);
        float phi = 2.0 * ENV_PI * xi.x, cos_theta = sqrt(1.0 - xi.y), sin_theta = sqrt(xi.y);
        vec3 l = vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
        c += pow(1.0 - clamp(dot(v, normalize(v + l)), 0.0, 1.0), 5.0);
    }
    imageStore(brdf_table, p, vec4(a / float(SAMPLES), b / float(SAMPLES), c / float(SAMPLES), 1.0));
}
