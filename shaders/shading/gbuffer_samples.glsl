// A multisampled G-buffer's pixel resolved (anti-aliasing; docs/DESIGN.md#anti-aliasing): its
// samples grouped by surface — equal G-buffer values, the samples one G-buffer fragment wrote —
// each group shaded once at the mean of its samples' points (its depth the mean of theirs: one
// plane's depth is affine in the image), the pixel the mean of its samples in the display's
// linear light. The deferred lighting subpass and deferred-compute's lighting read their
// samples differently: the includer defines `GBUFFER_LOAD(name, s)`, the G-buffer image `name`
// (depth, normal, object, albedo, roughness_metallic, emissive, lobes) at sample `s` of the
// pixel, `GBUFFER_MATERIAL` where the G-buffer has the roughness-metallic and emissive
// images and `GBUFFER_LOBES` where the lobes image; and `surface_display(xy, z, g)`, the
// display-linear colour of the surface `g` at the point `xy` (pixels) and depth `z`, after this
// header's structs and before `resolve_samples`. Needs visibility_samples.glsl.

#ifndef MANYLIGHTS_GBUFFER_SAMPLES_GLSL
#define MANYLIGHTS_GBUFFER_SAMPLES_GLSL

// What the G-buffer holds at a sample (0 without samples), depth aside.
struct GSample {
    vec2 normal;
    uint id;
    vec4 albedo;
    vec2 roughness_metallic;
    vec3 emissive_factor;
    float normal_spread; // in the emissive image's alpha
    uvec4 lobes;         // pack_lobe_texels (0 without)
};

GSample gbuffer_sample(int s) {
    GSample g;
    g.normal = GBUFFER_LOAD(normal, s).xy;
    g.id = GBUFFER_LOAD(object, s).r;
    g.albedo = GBUFFER_LOAD(albedo, s);
#ifdef GBUFFER_MATERIAL
    g.roughness_metallic = GBUFFER_LOAD(roughness_metallic, s).xy;
    vec4 emissive = GBUFFER_LOAD(emissive, s);
    g.emissive_factor = emissive.rgb;
    g.normal_spread = emissive.a;
#else
    g.roughness_metallic = vec2(1.0);
    g.emissive_factor = vec3(1.0);
    g.normal_spread = 0.0;
#endif
    g.lobes = uvec4(0u);
#ifdef GBUFFER_LOBES
    if (LOBE_TEXTURES) {
        g.lobes = GBUFFER_LOAD(lobes, s);
    }
#endif
    return g;
}

bool same_surface(GSample a, GSample b) {
    return a.normal == b.normal && a.id == b.id && a.albedo == b.albedo && a.roughness_metallic == b.roughness_metallic
        && a.emissive_factor == b.emissive_factor && a.normal_spread == b.normal_spread && a.lobes == b.lobes;
}

// The extensions' texels of `g` (no texture's where the G-buffer has none).
LobeTexels gsample_lobes(GSample g) {
    return LOBE_TEXTURES ? unpack_lobe_texels(g.lobes) : no_lobe_texels(oct_decode(g.normal));
}

// The display-linear colour of a surface point (the includer's; see above).
vec3 surface_display(vec2 xy, float z, GSample g);

// The pixel's samples resolved: the mean of their display-linear colours over every sample
// (the background's left out) and, in alpha, the share a surface covers.
vec4 resolve_samples(ivec2 pixel) {
    uint left = (1u << VISIBILITY_SAMPLES) - 1u;
    vec3 sum = vec3(0.0);
    uint covered = 0u;
    while (left != 0u) {
        int s = findLSB(left);
        left &= ~(1u << uint(s));
        float z = GBUFFER_LOAD(depth, s).r;
        if (z >= 1.0) {
            continue;
        }
        GSample g = gbuffer_sample(s);
        uint members = 1u << uint(s);
        float depth_sum = z;
        for (int t = s + 1; t < int(VISIBILITY_SAMPLES); t++) {
            float zt = GBUFFER_LOAD(depth, t).r;
            if ((left & (1u << uint(t))) != 0u && zt < 1.0 && same_surface(g, gbuffer_sample(t))) {
                members |= 1u << uint(t);
                depth_sum += zt;
            }
        }
        left &= ~members;
        uint count = uint(bitCount(members));
        sum += float(count) * surface_display(shading_xy(pixel, members), depth_sum / float(count), g);
        covered += count;
    }
    return vec4(sum, float(covered)) / float(VISIBILITY_SAMPLES);
}

#endif
