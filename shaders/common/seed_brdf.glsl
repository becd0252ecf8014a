// The `seed` shading model (docs/DESIGN.md#shading-models): specular-only Cook-Torrance.
// Mirrored on the CPU by crates/ml-cpu/src/shading.rs (keep in sync; tests compare them).

#ifndef MANYLIGHTS_SEED_BRDF_GLSL
#define MANYLIGHTS_SEED_BRDF_GLSL

const float PI = 3.14159265358979;

float d_ggx(float n_dot_h, float roughness) {
    float alpha = roughness * roughness;
    float alpha2 = alpha * alpha;
    float denom = n_dot_h * n_dot_h * (alpha2 - 1.0) + 1.0;
    return alpha2 / (PI * denom * denom);
}

// Schlick-Smith G divided by (4 NdotL NdotV). The seed computes G and then divides by
// 4 NdotL NdotV, which is 0/0 at grazing view; the quotient is the same number without the NaN.
float g_schlick_smith_over_4nlnv(float n_dot_l, float n_dot_v, float roughness) {
    float r = roughness + 1.0;
    float k = (r * r) / 8.0;
    return 0.25 / ((n_dot_l * (1.0 - k) + k) * (n_dot_v * (1.0 - k) + k));
}

vec3 f_schlick(float cos_theta, vec3 albedo, float metallic) {
    vec3 f0 = mix(vec3(0.04), albedo, metallic);
    return f0 + (1.0 - f0) * pow(1.0 - cos_theta, 5.0);
}

// One point light at a surface point, as the seed computes it: the cosines, the falloff
// (1 − d/r)², Schlick's F and the specular term D·F·G/(4·N·L·N·V). `reaches` is false beyond
// the radius or behind the surface (nothing else is set then).
struct SeedLightTerms {
    bool reaches;
    float n_dot_l;
    float falloff;
    vec3 f;
    vec3 spec;
};

SeedLightTerms seed_light_terms(PointLight light, vec3 world_pos, vec3 n, vec3 v, vec3 albedo, float roughness, float metallic) {
    SeedLightTerms t;
    t.reaches = false;
    vec3 light_vec = light.position_radius.xyz - world_pos;
    float dist = length(light_vec);
    float radius = light.position_radius.w;
    if (dist > radius) {
        return t;
    }
    vec3 l = light_vec / dist;
    vec3 h = normalize(v + l);
    float n_dot_v = clamp(dot(n, v), 0.0, 1.0);
    t.n_dot_l = clamp(dot(n, l), 0.0, 1.0);
    float n_dot_h = clamp(dot(n, h), 0.0, 1.0);
    if (t.n_dot_l <= 0.0) {
        return t;
    }
    t.reaches = true;
    float atten = clamp(1.0 - dist / radius, 0.0, 1.0);
    t.falloff = atten * atten;
    float d = d_ggx(n_dot_h, roughness);
    float g = g_schlick_smith_over_4nlnv(t.n_dot_l, n_dot_v, max(0.05, roughness));
    t.f = f_schlick(n_dot_v, albedo, metallic);
    t.spec = d * t.f * g;
    return t;
}

// Light reflected towards V by one point light under the seed's Cook–Torrance terms; exactly
// zero beyond the light's radius. `pbr` (a constant at every call, folded by the compiler)
// adds Lambert diffuse weighted by (1 − F)(1 − metallic) and uses radiance falloff·N·L once;
// without it this is the seed model, whose radiance is falloff·N·L and which multiplies by
// N·L once more. One straight-line function with early returns on purpose: returning the
// shared terms in a struct instead made the seed's forward pass 1.44× slower on the H100.
vec3 cook_torrance_point_light(PointLight light, vec3 world_pos, vec3 n, vec3 v, vec3 albedo, float roughness, float metallic,
                               bool pbr) {
    vec3 light_vec = light.position_radius.xyz - world_pos;
    float dist = length(light_vec);
    float radius = light.position_radius.w;
    if (dist > radius) {
        return vec3(0.0);
    }
    vec3 l = light_vec / dist;
    vec3 h = normalize(v + l);
    float n_dot_v = clamp(dot(n, v), 0.0, 1.0);
    float n_dot_l = clamp(dot(n, l), 0.0, 1.0);
    float n_dot_h = clamp(dot(n, h), 0.0, 1.0);
    if (n_dot_l <= 0.0) {
        return vec3(0.0);
    }
    float atten = clamp(1.0 - dist / radius, 0.0, 1.0);
    float radiance = atten * atten * n_dot_l;
    float d = d_ggx(n_dot_h, roughness);
    float g = g_schlick_smith_over_4nlnv(n_dot_l, n_dot_v, max(0.05, roughness));
    vec3 f = f_schlick(n_dot_v, albedo, metallic);
    vec3 spec = d * f * g;
    if (pbr) {
        vec3 diffuse = (1.0 - f) * (1.0 - metallic) * albedo / PI;
        return (diffuse + spec) * light.color.rgb * radiance;
    }
    return spec * n_dot_l * light.color.rgb * radiance;
}

// The `seed` model: specular only (docs/DESIGN.md#shading-models).
vec3 seed_point_light(PointLight light, vec3 world_pos, vec3 n, vec3 v, vec3 albedo, float roughness, float metallic) {
    return cook_torrance_point_light(light, world_pos, n, v, albedo, roughness, metallic, false);
}

// The `pbr` model (docs/DESIGN.md#shading-models): the seed model's specular term plus Lambert
// diffuse.
vec3 pbr_point_light(PointLight light, vec3 world_pos, vec3 n, vec3 v, vec3 albedo, float roughness, float metallic) {
    return cook_torrance_point_light(light, world_pos, n, v, albedo, roughness, metallic, true);
}

#endif
