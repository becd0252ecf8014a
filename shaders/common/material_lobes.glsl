// The pbr model with glTF's PBR extensions (lighting.glsl, under MATERIAL_LOBES): a
// dielectric's reflectance from its index of refraction, scaled and tinted by its specular
// factor and colour; cloth-like sheen (the Charlie distribution and visibility, Estevez and
// Kulla 2017); a clear coat over the base; unlit surfaces. With every lobe at its default
// the light is the pbr model's own, the same formulas rearranged.
// ml_cpu::material_lobes is the CPU reference (keep in sync; tests compare them).
// Needs seed_brdf.glsl and environment/environment.glsl.

#ifndef MANYLIGHTS_MATERIAL_LOBES_GLSL
#define MANYLIGHTS_MATERIAL_LOBES_GLSL


// Pipelines of scenes with an object whose material has lobes (the others compile the pbr
// model's plain light: its cost at a million lights stays what it was).
layout(constant_id = 45) const bool MATERIAL_LOBES = false;

// PointMaterial's lobes (ObjectData.lobes): specular: (dielectric F₀, specular factor);
// coat: (clear coat, its roughness, unlit, transmission); sheen: (colour, roughness). The
// fourth, the volume's transmittance, only the transparent layers read (layers.glsl).
const float SHEEN_MIN_ROUGHNESS = 0.07;

float d_charlie(float n_dot_h, float roughness) {
    float r = max(roughness, SHEEN_MIN_ROUGHNESS);
    float inv_alpha = 1.0 / (r * r);
    float sin2 = max(1.0 - n_dot_h * n_dot_h, 0.0);
    return (2.0 + inv_alpha) * pow(sin2, 0.5 * inv_alpha) / (2.0 * PI);
}

float lambda_sheen_fit(float x, float t) {
    return mix(21.5473, 25.3245, t) / (1.0 + mix(3.82987, 3.32435, t) * pow(x, mix(0.19823, 0.16801, t))) + mix(-1.97760, -1.27393, t) * x +
           mix(-4.32054, -4.85967, t);
}

float lambda_sheen(float cos_theta, float alpha) {
    float t = (1.0 - alpha) * (1.0 - alpha);
    return cos_theta < 0.5 ? exp(lambda_sheen_fit(cos_theta, t)) : exp(2.0 * lambda_sheen_fit(0.5, t) - lambda_sheen_fit(1.0 - cos_theta, t));
}

// G / (4 n·l n·v) of the Charlie sheen, at most 1.
float v_charlie(float n_dot_l, float n_dot_v, float roughness) {
    float r = max(roughness, SHEEN_MIN_ROUGHNESS);
    float alpha = r * r;
    return clamp(1.0 / ((1.0 + lambda_sheen(n_dot_v, alpha) + lambda_sheen(n_dot_l, alpha)) * (4.0 * n_dot_v * n_dot_l)), 0.0, 1.0);
}

// The sheen's directional albedo E(n·v, roughness): bilinear in the table of 16×16 entries
// EnvironmentData carries (row: roughness, column: n·v, each 0 to 1 in 15 steps). A storage
// buffer, not a constant array: lavapipe compiled a constant array indexed at run time for
// minutes.
const int SHEEN_TABLE_SIZE = 16;

float sheen_entry(int i) {
    return environment.sheen_albedo[i];
}

float sheen_albedo(float n_dot_v, float roughness) {
    float top = float(SHEEN_TABLE_SIZE - 1);
    float x = clamp(n_dot_v, 0.0, 1.0) * top, y = clamp(roughness, 0.0, 1.0) * top;
    float x0 = min(floor(x), top - 1.0), y0 = min(floor(y), top - 1.0);
    float fx = x - x0, fy = y - y0;
    int i = int(y0) * SHEEN_TABLE_SIZE + int(x0);
    float low = sheen_entry(i) + (sheen_entry(i + 1) - sheen_entry(i)) * fx;
    float high = sheen_entry(i + SHEEN_TABLE_SIZE) + (sheen_entry(i + SHEEN_TABLE_SIZE + 1) - sheen_entry(i + SHEEN_TABLE_SIZE)) * fx;
    return low + (high - low) * fy;
}

// The clear coat's Fresnel reflectance at n·v (F₀ 0.04), times its strength `coat`.
float coat_fresnel(float n_dot_v, float coat) {
    return coat * (0.04 + 0.96 * pow(1.0 - n_dot_v, 5.0));
}

float max3(vec3 c) {
    return max(max(c.r, c.g), c.b);
}

// A dielectric's Fresnel reflectance at Schlick's weight `fc` = (1 − n·v)⁵: its F₀ and
// specular factor (`specular`) applied.
vec3 dielectric_fresnel(vec4 specular, float fc) {
    return specular.a * (specular.rgb + (1.0 - specular.rgb) * fc);
}

// One point light in the pbr model with lobes (zero beyond the radius and behind the
// surface): F = mix(specular·Schlick(dielectric F₀), Schlick(albedo), metallic), Lambert
// diffuse weighted by (1 − F)(1 − metallic)(1 − transmission) plus GGX; the sheen's lobe over
// the base scaled by 1 − max(sheen)·E at the view and the light; the clear coat's GGX lobe
// (F₀ 0.04) over the base scaled by 1 − coat·F_coat, its cosines about its own normal
// `coat_n`. Its first lines are cook_torrance_point_light's (seed_brdf.glsl), repeated: a
// shared helper returning the cosines in a struct made the seed's forward pass 1.44× slower
// on the H100.
vec3 lobed_point_light(PointLight light, vec3 world_pos, vec3 n, vec3 v, vec3 albedo, float roughness, float metallic, vec4 specular,
                       vec4 coat, vec3 coat_n, vec4 sheen) {
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
    float fc = pow(1.0 - n_dot_v, 5.0);
    vec3 f_dielectric = dielectric_fresnel(specular, fc);
    vec3 f_metal = albedo + (1.0 - albedo) * fc;
    vec3 f = mix(f_dielectric, f_metal, metallic);
    float g = g_schlick_smith_over_4nlnv(n_dot_l, n_dot_v, max(0.05, roughness));
    vec3 base = (1.0 - f) * (1.0 - metallic) * (1.0 - coat.w) * albedo / PI + d_ggx(n_dot_h, roughness) * f * g;
    float sheen_max = max3(sheen.rgb);
    if (sheen_max > 0.0) {
        base *= min(1.0 - sheen_max * sheen_albedo(n_dot_v, sheen.a), 1.0 - sheen_max * sheen_albedo(n_dot_l, sheen.a));
        base += sheen.rgb * d_charlie(n_dot_h, sheen.a) * v_charlie(n_dot_l, n_dot_v, sheen.a);
    }
    if (coat.x <= 0.0) {
        return base * light.color.rgb * radiance;
    }
    float coat_v = clamp(dot(coat_n, v), 0.0, 1.0), coat_l = clamp(dot(coat_n, l), 0.0, 1.0), coat_h = clamp(dot(coat_n, h), 0.0, 1.0);
    float f_coat = coat_fresnel(coat_v, coat.x);
    float coat_lobe = coat_l > 0.0 ? f_coat * d_ggx(coat_h, coat.y) * g_schlick_smith_over_4nlnv(coat_l, coat_v, max(0.05, coat.y)) : 0.0;
    return (base * (1.0 - f_coat) * radiance + vec3(coat_lobe * atten * atten * coat_l)) * light.color.rgb;
}

// What the clear coat (normal `coat_n`) lets through of what lies under it (light given off
// included): 1 − coat·F_coat at the view.
float coat_transmittance(vec3 coat_n, vec3 v, vec4 coat) {
    return 1.0 - coat_fresnel(clamp(dot(coat_n, v), 0.0, 1.0), coat.x);
}

// What the surface lets through of the light behind it (KHR_materials_transmission, thin
// walled): transmission × (1 − metallic) × albedo × (1 − F) of the dielectric's Fresnel
// term × 1 − coat·F_coat (about the coat's normal `coat_n`) × the volume's transmittance
// `volume` (ml_cpu lobed_transmittance).
vec3 lobed_transmittance(vec3 n, vec3 v, vec3 albedo, float metallic, vec4 specular, vec4 coat, vec3 coat_n, vec3 volume) {
    float n_dot_v = clamp(dot(n, v), 0.0, 1.0);
    vec3 f_dielectric = dielectric_fresnel(specular, pow(1.0 - n_dot_v, 5.0));
    return (1.0 - f_dielectric) * albedo * volume * (coat.w * (1.0 - metallic) * coat_transmittance(coat_n, v, coat));
}

// Environment light with lobes (environment.glsl's split sum): the specular term's F₀ and F₉₀
// from the dielectric's F₀ and specular factor, the diffuse less what is transmitted and what
// the dielectric's Fresnel term reflects; the sheen's lobe as E(n·v)·sheen colour times the
// radiance prefiltered at its roughness about the normal, the base scaled by
// 1 − max(sheen)·E; the clear coat's split sum at its roughness about its own normal
// `coat_n` over the base scaled by 1 − coat·F_coat.
vec3 lobed_environment_light(vec3 n, vec3 v, vec3 albedo, float roughness, float metallic, float occlusion, vec4 specular, vec4 coat,
                             vec3 coat_n, vec4 sheen) {
    mat3 to_image = environment_to_image();
    float n_dot_v = clamp(dot(n, v), 0.0, 1.0);
    vec3 r = normalize(2.0 * dot(n, v) * n - v);
    vec3 ab = environment_brdf_at(n_dot_v, roughness);
    vec3 diffuse = albedo * (1.0 - metallic) * (1.0 - coat.w) * (1.0 - dielectric_fresnel(specular, ab.z)) * environment_diffuse(to_image * n) * occlusion;
    vec3 f0 = mix(specular.a * specular.rgb, albedo, metallic);
    float f90 = mix(specular.a, 1.0, metallic);
    vec3 prefiltered = environment_prefiltered(to_image * dominant_direction(n, r, roughness), roughness);
    vec3 base = diffuse + prefiltered * (f0 * ab.x + f90 * ab.y) * specular_occlusion(n_dot_v, occlusion, roughness);
    float sheen_max = max3(sheen.rgb);
    if (sheen_max > 0.0) {
        float e = sheen_albedo(n_dot_v, sheen.a);
        base = base * (1.0 - sheen_max * e) + sheen.rgb * e * environment_prefiltered(to_image * n, sheen.a) * occlusion;
    }
    if (coat.x > 0.0) {
        float coat_v = clamp(dot(coat_n, v), 0.0, 1.0);
        vec3 coat_r = normalize(2.0 * dot(coat_n, v) * coat_n - v);
        vec2 coat_ab = environment_brdf_at(coat_v, coat.y).xy;
        vec3 coat_light = environment_prefiltered(to_image * dominant_direction(coat_n, coat_r, coat.y), coat.y) * (0.04 * coat_ab.x + coat_ab.y) *
                          specular_occlusion(coat_v, occlusion, coat.y);
        base = base * (1.0 - coat_fresnel(coat_v, coat.x)) + coat.x * coat_light;
    }
    return base * environment.params.x;
}

#endif
