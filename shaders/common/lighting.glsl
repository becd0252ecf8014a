// The light loop every shading path shares (forward and clustered fragment shaders, the
// deferred lighting subpass, the deferred-compute pass): one BRDF source and, for every path
// but the light grid's, one summation order (ascending light index), so culling and deferring
// change no pixel; the light grid sums a cell's lights in the order its build's atomics left
// them, which moves a pixel by at most a rounding step.
//
// The includer includes scene_bindings.glsl (`frame`, `lights[]`, with CLUSTERED the cluster
// lists, with LIGHT_GRID the light grid's) and textures.glsl.

#ifndef MANYLIGHTS_LIGHTING_GLSL
#define MANYLIGHTS_LIGHTING_GLSL

#include "common/shading_model.glsl"
#include "common/seed_brdf.glsl"
#include "shadows/omni_shadow.glsl"
#include "common/blinn_phong.glsl"
#include "clusters/cluster.glsl"
#include "common/world_from_depth.glsl"
#include "environment/environment.glsl"
#include "common/material_lobes.glsl"
#include "common/background.glsl"
#ifdef LIGHT_GRID
#include "light_grid/light_grid.glsl"
#endif

// Sum LIGHT(light) over every light that may reach the point: the cluster's lights in
// ascending index order, the light grid's near the point, or all of them. A macro, so that
// LIGHT (a model's light with its shadow) is written into the loop itself.
#ifdef CLUSTERED
#define SUM_LIGHTS(sum, LIGHT)                                                   \
    {                                                                            \
        float depth_ = -(frame.view * vec4(world, 1.0)).z;                       \
        ClusterRange range_ = cluster_ranges[cluster_of(frame, frag_xy, depth_)]; \
        for (uint k_ = 0u; k_ < range_.count; ++k_) {                           \
            uint i_ = light_indices[range_.offset + k_];                         \
            sum += LIGHT(lights[i_]) * spot_cone(i_, lights[i_], world);         \
        }                                                                        \
    }
#elif defined(LIGHT_GRID)
#define SUM_LIGHTS(sum, LIGHT)                                                            \
    GRID_FOR_LIGHTS(GRID_LIGHT(sum, LIGHT, k_))

// Light k_ of the grid's lists, its colour read only where it may reach `world` (beyond the
// radius every model gives exactly nothing: the same test they make first).
#define GRID_LIGHT(sum, LIGHT, k)                                                            \
    {                                                                                        \
        vec4 p_ = grid_light_positions[k];                                                   \
        if (!(length(p_.xyz - world) > p_.w)) {                                              \
            PointLight l_ = PointLight(p_, grid_light_colors[k]);                            \
            sum += LIGHT(l_) * spot_cone(SPOT_LIGHTS ? grid_scene_index[k] : 0u, l_, world); \
        }                                                                                    \
    }
#else
#define SUM_LIGHTS(sum, LIGHT)                                         \
    for (uint i_ = 0u; i_ < frame.light_count; ++i_) {               \
        sum += LIGHT(lights[i_]) * spot_cone(i_, lights[i_], world);   \
    }
#endif

// Scenes with spot lights (a specialization constant: the others run the loop they always ran).
layout(constant_id = 14) const bool SPOT_LIGHTS = false;

// How much of light `i`'s cone reaches `world` (1 for point lights and scenes without spots).
float spot_cone(uint i, PointLight l, vec3 world) {
    if (SPOT_LIGHTS) {
        LightCone c = light_cones[i];
        float cos_to_axis = dot(normalize(world - l.position_radius.xyz), c.direction_scale.xyz);
        float f = clamp(cos_to_axis * c.direction_scale.w + c.offset.x, 0.0, 1.0);
        return f * f;
    }
    return 1.0;
}

// Add LIGHT(light) for every directional light: each as a point light 10 km away with a
// radius of 10³⁰ m, so every model's own point-light code applies with a falloff of exactly 1
// (1 − 10⁴/10³⁰ rounds to 1) and a direction off by under 10⁻⁷ rad. With shadow rays each
// casts its shadow as a point light does: a ray 10 km long towards it.
#define SUM_DIRECTIONAL(sum, LIGHT)                                                                   \
    for (uint d_ = 0u; d_ < frame.directional_count; ++d_) {                                           \
        PointLight far_ = PointLight(vec4(world - directional_lights[d_].direction.xyz * 1e4, 1e30), \
                                     vec4(directional_lights[d_].color.rgb, directional_shadow_slot())); \
        sum += LIGHT(far_);                                                                            \
    }

// What a directional light's PointLight carries as its shadow slot (omni_shadow.glsl): with
// shadow rays any non-zero value casts (no slot is read); with maps, whose cubes and tiles
// cannot hold a light 10 km away, a ray's (DIRECTIONAL_RAYS); without shadows none.
float directional_shadow_slot() {
    if (SHADOW_RAYS) {
        return 1.0;
    }
    if (DIRECTIONAL_RAYS) {
        return DIRECTIONAL_RAY_SLOT;
    }
    return 0.0;
}

// What a surface point is shaded with: the object's material (ObjectData's or ObjectPush's
// vectors) times the factors its textures give (Surface, or their copy in the G-buffer), and
// under MATERIAL_LOBES its lobes (material_lobes.glsl).
struct PointMaterial {
    vec3 albedo;
    float roughness;
    float metallic;
    float occlusion;
    vec3 emission;
    vec4 specular;
    vec4 coat;
    vec4 sheen;
    vec3 coat_normal;
    // Multiplies the volume's thickness (its transmittance's exponent).
    float thickness;
};

// The roughness of a surface whose normals spread by `spread` (surface.glsl normal_spread)
// within the pixel: the microfacets' slope variance (GGX α² = roughness⁴) plus theirs, twice
// over (Toksvig's widened Blinn-Phong exponent, 1/s' = 1/s + σ², with s ≈ 2/α²).
float widened_roughness(float roughness, float spread) {
    if (spread == 0.0) {
        return roughness;
    }
    float alpha = roughness * roughness;
    return sqrt(sqrt(min(alpha * alpha + 2.0 * spread * spread, 1.0)));
}

// `object`: its index in the object buffer (whose lobes it reads, each factor times its
// texel in `t`; the dielectric's F₀ clamped to 1 after its colour's texel).
PointMaterial point_material(vec4 albedo_roughness, vec4 material, vec4 emissive, vec4 albedo_occlusion, vec2 roughness_metallic,
                             vec3 emissive_factor, float normal_spread, uint object, LobeTexels t) {
    PointMaterial m;
    if (MATERIAL_LOBES) {
        vec4 specular = objects[object].lobes[0];
        vec4 coat = objects[object].lobes[1];
        m.specular = vec4(min(specular.rgb * t.specular.rgb, vec3(1.0)), specular.a * t.specular.a);
        m.coat = vec4(coat.xy * t.coat, coat.z, coat.w * t.transmission.x);
        m.sheen = objects[object].lobes[2] * t.sheen;
        m.coat_normal = t.coat_normal;
        m.thickness = t.transmission.y;
    }
    m.albedo = albedo_roughness.rgb * albedo_occlusion.rgb;
    m.roughness = widened_roughness(albedo_roughness.a * roughness_metallic.x, normal_spread);
    m.metallic = material.x * roughness_metallic.y;
    m.occlusion = albedo_occlusion.a;
    m.emission = emissive.rgb * emissive_factor;
    return m;
}

// The unit vector from `world` towards the eye; an orthographic camera looks along its axis
// everywhere (the view matrix's third row is the eye's +Z, its back, in world space).
vec3 toward_eye(vec3 world) {
    vec3 back = vec3(frame.view[0][2], frame.view[1][2], frame.view[2][2]);
    return frame.camera_pos.w != 0.0 ? normalize(frame.camera_pos.xyz - world) : back;
}

// One light's contribution under the shading model. The models are specialization constants,
// so a pipeline keeps one model's code and the light loops below are that model's own loops
// (a model switch on a uniform inside the loop cost the seed model 1.4–1.8× on the H100).
// One loop for every model, not one each: a light's shadow (shadowed: rays, cubes, atlas)
// then appears once per loop, where a loop per model repeated it eight times — and lavapipe
// inlines every call before it drops the models a pipeline does not use, so the lighting
// pipelines took three times as long to make.
vec3 model_point_light(PointLight l, vec3 world, vec3 n, vec3 v, PointMaterial m, vec3 r0, float shininess, vec3 coat_n) {
    if (MODEL_BLINN_PHONG) {
        return bp_point_light(l, world, n, v, m.albedo, r0, shininess);
    }
    if (MODEL_PBR) {
        if (MATERIAL_LOBES) {
            return lobed_point_light(l, world, n, v, m.albedo, m.roughness, m.metallic, m.specular, m.coat, coat_n, m.sheen);
        }
        return pbr_point_light(l, world, n, v, m.albedo, m.roughness, m.metallic);
    }
    return seed_point_light(l, world, n, v, m.albedo, m.roughness, m.metallic);
}

// Linear colour of a surface point: every light that reaches it plus what the model adds
// (seed, pbr: ambient, times the occlusion, or pbr's environment light; blinn-phong: ambient,
// sun, spot, reflection) plus the light it gives off (`emission`); pbr with lobes as
// material_lobes.glsl has it (an unlit surface: its albedo). `frag_xy` is the pixel centre
// (gl_FragCoord.xy), which picks the cluster.
vec3 shade_point(vec3 world, vec3 n, PointMaterial m, vec2 frag_xy) {
    ray_steps = 0u; // the ray-cost view's count is this point's (a lane may shade several)
    vec3 albedo = m.albedo, emission = m.emission;
    float roughness = m.roughness, metallic = m.metallic, occlusion = m.occlusion;
    vec3 v = toward_eye(world);
    // Blinn-phong's specular colour and exponent.
    vec3 r0 = mix(vec3(0.04), albedo, metallic);
    float shininess = 1.0 - roughness;
    // The lobes' coat normal; a surface unlit by its material shows its albedo. (One model's
    // constant is set at most.)
    vec3 coat_n = n;
    if (MODEL_PBR) {
        // Nested, not `&&`: a constant expression of two specialization constants is an
        // OpSpecConstantOp the SPIR-V reflection cannot evaluate.
        if (MATERIAL_LOBES) {
            if (m.coat.z != 0.0) {
                return albedo;
            }
            coat_n = LOBE_TEXTURES ? m.coat_normal : n;
        }
    }
    vec3 lo = vec3(0.0);
#define MODEL_LIGHT(l) shadowed(model_point_light(l, world, n, v, m, r0, shininess, coat_n), l, world, n)
    SUM_LIGHTS(lo, MODEL_LIGHT)
    SUM_DIRECTIONAL(lo, MODEL_LIGHT)
    if (MODEL_BLINN_PHONG) {
        return bp_scene_lights(world, n, v, albedo, r0, shininess) + lo + emission;
    }
    if (MODEL_PBR) {
        if (MATERIAL_LOBES) {
            float under_coat = coat_transmittance(coat_n, v, m.coat);
            if (ENVIRONMENT) {
                return lobed_environment_light(n, v, albedo, roughness, metallic, occlusion, m.specular, m.coat, coat_n, m.sheen) + lo +
                       emission * under_coat;
            }
            return albedo * frame.ambient * occlusion * (1.0 - m.coat.w) * under_coat + lo + emission * under_coat;
        }
        if (ENVIRONMENT) {
            return environment_light(n, v, albedo, roughness, metallic, occlusion) + lo + emission;
        }
    }
    return albedo * frame.ambient * occlusion + lo + emission;
}

// Steps the ray-cost view's heat scale ends at (tables.rs says so in its legend).
const float RAY_COST_TOP = 1024.0;

// A debug view's display value (0 to 1) as the linear colour encode_gamma turns back into it.
vec3 debug_shown(vec3 display) {
    return pow(clamp(display, 0.0, 1.0), vec3(2.2));
}

// The surface debug views (G-buffer channels, depth): what the view shows at a surface point
// as linear colour, which encode_gamma turns into the promised display values — albedo as
// it is, normal·0.5 + 0.5, (roughness, metallic, 0), and ln(depth/near)/ln(far/near) in grey.
// False for any other view. Every shading path calls it with the values it would shade with.
bool debug_surface(vec3 world, vec3 n, vec3 albedo, float roughness, float metallic, uint object_flags, vec2 frag_xy, out vec3 color) {
    uint view = frame.viewport.z;
    vec3 display;
    if (view == DEBUG_VIEW_ALPHA) {
        // Which surfaces an alpha mask cuts: opaque grey, masked green, blended (drawn as a
        // mask) orange; double-sided ones brighter.
        bool masked = (object_flags & OBJECT_MASKED) != 0u, blended = (object_flags & OBJECT_BLENDED) != 0u;
        display = blended ? vec3(1.0, 0.5, 0.1) : masked ? vec3(0.2, 0.9, 0.2) : vec3(0.45);
        display *= (object_flags & OBJECT_DOUBLE_SIDED) != 0u ? 1.0 : 0.7;
    } else if (view == DEBUG_VIEW_GBUFFER_ALBEDO) {
        color = albedo;
        return true;
    } else if (view == DEBUG_VIEW_GBUFFER_NORMAL) {
        display = n * 0.5 + 0.5;
    } else if (view == DEBUG_VIEW_GBUFFER_MATERIAL) {
        display = vec3(roughness, metallic, 0.0);
    } else if (view == DEBUG_VIEW_DEPTH) {
        float depth = -(frame.view * vec4(world, 1.0)).z;
        display = vec3(log(depth / frame.cluster_frustum.x) / log(frame.cluster_frustum.y / frame.cluster_frustum.x));
    } else {
        return false;
    }
    color = debug_shown(display);
    return true;
}

// The ray-cost view, which the shading path shows in place of the colour of a point it has just
// shaded (shade_point): the traversal steps of the point's shadow rays on a log scale up to
// RAY_COST_TOP, as display-linear colour (what debug_surface gives). Shading traces the rays,
// so the view shows what the frame traces, and no loop over the lights is written for it
// alone (on lavapipe, every copy of the light loop and its shadow code costs time to make the
// pipeline). False, leaving `color`, for any other view.
bool ray_cost_shown(inout vec3 color) {
    if (frame.viewport.z != DEBUG_VIEW_RAY_COST) {
        return false;
    }
    color = debug_shown(heat(log2(1.0 + float(ray_steps)) / log2(1.0 + RAY_COST_TOP)));
    return true;
}

// Lights the fragment tests: its cluster's, or the light grid's near it (the cluster-heat
// debug view).
#ifdef CLUSTERED
uint cluster_light_count(vec3 world, vec2 frag_xy) {
    float depth = -(frame.view * vec4(world, 1.0)).z;
    return cluster_ranges[cluster_of(frame, frag_xy, depth)].count;
}
#elif defined(LIGHT_GRID)
uint cluster_light_count(vec3 world, vec2 frag_xy) {
    uint count = 0u;
    GRID_FOR_LIGHTS(count += 1u;)
    return count;
}
#endif

#endif
