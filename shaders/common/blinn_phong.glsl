// The `blinn-phong` shading model, the "DX12 book" lighting (docs/DESIGN.md#shading-models):
// linear falloff, Lambert, Blinn-Phong specular with shininess = (1 − roughness)·256 normalised
// by (m + 8)/8, Schlick Fresnel on the half vector; a directional light with a 3×3 PCF shadow
// map, point lights, one spot light, ambient, and an environment reflection weighted by
// shininess × Fresnel. Unlike the demo this model comes from, the shadow darkens only the light
// that casts it, and the specular term is not tinted by the diffuse texture.
// Needs common.glsl, scene_bindings.glsl and textures.glsl.

#ifndef MANYLIGHTS_BLINN_PHONG_GLSL
#define MANYLIGHTS_BLINN_PHONG_GLSL

vec3 bp_schlick(vec3 r0, vec3 n, vec3 l) {
    float f = 1.0 - clamp(dot(n, l), 0.0, 1.0);
    return r0 + (1.0 - r0) * (f * f * f * f * f);
}

// (diffuse + specular) × strength for light arriving along l (unit, towards the light).
vec3 bp_brdf(vec3 strength, vec3 l, vec3 n, vec3 v, vec3 diffuse, vec3 r0, float shininess) {
    float m = max(shininess * 256.0, 1e-3);
    vec3 h = normalize(v + l);
    float roughness_factor = (m + 8.0) * pow(max(dot(h, n), 0.0), m) / 8.0;
    return (diffuse + bp_schlick(r0, h, l) * roughness_factor) * strength;
}

// A radius-limited point light: falloff saturate((range − d)/range), zero beyond its radius.
vec3 bp_point_light(PointLight light, vec3 world, vec3 n, vec3 v, vec3 diffuse, vec3 r0, float shininess) {
    vec3 to_light = light.position_radius.xyz - world;
    float d = length(to_light);
    float range = light.position_radius.w;
    if (d > range) {
        return vec3(0.0);
    }
    vec3 l = to_light / d;
    float falloff = clamp((range - d) / range, 0.0, 1.0);
    return bp_brdf(light.color.rgb * max(dot(l, n), 0.0) * falloff, l, n, v, diffuse, r0, shininess);
}

// The sun's shadow is a shadow ray (--sun-shadow rays): no map.
layout(constant_id = 22) const bool SUN_RAYS = false;

// Fraction of the sun that reaches `world`: 3×3 PCF, one shadow-map texel apart, through the
// comparison sampler. The lookup point moves 1.5 texels along the normal first (normal-offset
// bias: no acne on lit surfaces, no visible gap at contact). With SUN_RAYS: a shadow ray from
// the point toward the sun, longer than the scene's box is wide (shadows/shadow_rays.glsl).
float bp_sun_visibility(vec3 world, vec3 n) {
    if (SUN_RAYS) {
        vec3 origin = ray_origin(world, n);
        return ray_occluded(origin, origin - frame.sun_direction.xyz * frame.shadow_rays.x) ? 0.0 : 1.0;
    }
    vec4 c = frame.shadow_view_proj * vec4(world + n * (1.5 * frame.sun_strength.w), 1.0);
    vec3 p = c.xyz / c.w;
    vec2 uv = p.xy * 0.5 + 0.5;
    float texel = frame.sun_direction.w;
    float lit = 0.0;
    for (int y = -1; y <= 1; ++y) {
        for (int x = -1; x <= 1; ++x) {
            lit += textureLod(shadow_map, vec3(uv + vec2(x, y) * texel, p.z), 0.0);
        }
    }
    return lit / 9.0;
}

// Everything but the point lights: ambient, sun (shadowed), spot, environment reflection.
vec3 bp_scene_lights(vec3 world, vec3 n, vec3 v, vec3 diffuse, vec3 r0, float shininess) {
    vec3 color = frame.ambient_light.rgb * diffuse;
    vec3 sun_l = -frame.sun_direction.xyz;
    vec3 sun = bp_brdf(frame.sun_strength.rgb * max(dot(sun_l, n), 0.0), sun_l, n, v, diffuse, r0, shininess);
    // (Its shadow only where the sun lights the point: no ray where it would be multiplied by
    // zero anyway.)
    if (sun != vec3(0.0)) {
        color += sun * bp_sun_visibility(world, n);
    }
    // The spot light is a point light (same range and falloff) dimmed by its cone.
    vec3 spot_l = normalize(frame.spot_position_range.xyz - world);
    float cone = pow(max(dot(-spot_l, frame.spot_direction_power.xyz), 0.0), frame.spot_direction_power.w);
    PointLight spot = PointLight(frame.spot_position_range, vec4(frame.spot_strength.rgb * cone, 0.0));
    color += bp_point_light(spot, world, n, v, diffuse, r0, shininess);
    vec3 r = reflect(-v, n);
    color += shininess * bp_schlick(r0, n, r) * textureLod(sky, r, 0.0).rgb;
    return color;
}

#endif
