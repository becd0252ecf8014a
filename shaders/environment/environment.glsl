// Environment light at a surface point (lighting.glsl's pbr model, with ENVIRONMENT): the
// split sum (Karis 2013). Diffuse: albedo·(1 − metallic) times the nine coefficients' sum at
// the normal, times the ambient occlusion, less what the Fresnel term reflects of light from
// every direction (glTF's 1 − F(v·h), averaged). Specular: the cube prefiltered for the
// roughness towards the lobe's dominant direction times F₀·A + B from the BRDF table, times
// the specular occlusion the ambient occlusion implies (Lagarde and de Rousiers 2014), so
// interiors do not shine.
// ml_cpu::environment::environment_light is the CPU reference.

#ifndef MANYLIGHTS_ENVIRONMENT_GLSL
#define MANYLIGHTS_ENVIRONMENT_GLSL

#include "environment/environment_maps.glsl"

layout(set = 1, binding = 9) uniform samplerCube environment_specular;
layout(set = 1, binding = 10) uniform sampler2D environment_brdf;
layout(std430, set = 1, binding = 11) readonly buffer EnvironmentBuffer { EnvironmentData environment; };
// The image as a cube with its box mip chain (the background, common/background.glsl).
layout(set = 1, binding = 12) uniform samplerCube environment_radiance;

// Pipelines of scenes lit by an environment (the others keep their constant ambient term).
layout(constant_id = 44) const bool ENVIRONMENT = false;

// World directions → the image's frame (its turn about +Y).
mat3 environment_to_image() {
    return mat3(environment.to_image[0].xyz, environment.to_image[1].xyz, environment.to_image[2].xyz);
}

vec3 environment_diffuse(vec3 n) {
    float y[9];
    sh9_basis(n, y);
    vec3 sum = vec3(0.0);
    for (int k = 0; k < 9; ++k) {
        sum += environment.sh[k].rgb * y[k];
    }
    return max(sum, vec3(0.0));
}

float specular_occlusion(float n_dot_v, float occlusion, float roughness) {
    if (occlusion >= 1.0) {
        return 1.0;
    }
    return clamp(pow(n_dot_v + occlusion, exp2(-16.0 * roughness - 1.0)) - 1.0 + occlusion, 0.0, 1.0);
}

// The BRDF table at n·v and roughness: the split sum's (A, B) and the diffuse layer's mean
// Schlick weight (environment_brdf.comp).
vec3 environment_brdf_at(float n_dot_v, float roughness) {
    vec2 table = vec2(textureSize(environment_brdf, 0));
    return textureLod(environment_brdf, (vec2(n_dot_v, roughness) * (table - 1.0) + 0.5) / table, 0.0).xyz;
}

// The radiance prefiltered for `roughness` towards image direction `d`.
vec3 environment_prefiltered(vec3 d, float roughness) {
    return textureLod(environment_specular, d, roughness * environment.params.y).rgb;
}

// Where a GGX lobe of `roughness` about the reflection `r` of the view in `n` gathers most
// of its light: the rougher the surface, the nearer the normal (the split sum prefilters
// about r as if v = n; a rough lobe seen aslant leans towards n; Lagarde and de Rousiers
// 2014, as Filament writes it: r towards n by roughness²).
vec3 dominant_direction(vec3 n, vec3 r, float roughness) {
    return normalize(mix(r, n, roughness * roughness));
}

// `n`, `v`: unit normal and direction towards the eye, in the world.
vec3 environment_light(vec3 n, vec3 v, vec3 albedo, float roughness, float metallic, float occlusion) {
    mat3 to_image = environment_to_image();
    float n_dot_v = clamp(dot(n, v), 0.0, 1.0);
    vec3 r = normalize(2.0 * dot(n, v) * n - v);
    vec3 ab = environment_brdf_at(n_dot_v, roughness);
    // The diffuse layer less what the dielectric's Fresnel term reflects (F₀ 0.04).
    vec3 diffuse = albedo * (1.0 - metallic) * (1.0 - (0.04 + 0.96 * ab.z)) * environment_diffuse(to_image * n) * occlusion;
    vec3 f0 = mix(vec3(0.04), albedo, metallic);
    vec3 prefiltered = environment_prefiltered(to_image * dominant_direction(n, r, roughness), roughness);
    vec3 specular = prefiltered * (f0 * ab.x + ab.y) * specular_occlusion(n_dot_v, occlusion, roughness);
    return (diffuse + specular) * environment.params.x;
}

#endif
