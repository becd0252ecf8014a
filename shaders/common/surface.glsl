// What the rasterised surface contributes before lighting (forward fragment shaders and the
// G-buffer pass alike): an object's own base-colour texture and normal map (glTF), and
// blinn-phong's albedo texture and normal map; normal maps perturb the normal through the
// tangent frame (TBN); glTF's metallic-roughness, occlusion and emissive textures, and its PBR
// extensions' (LOBE_TEXTURES: the clear coat's own normal map among them). The seed model's
// built-in objects use none.
// Needs common.glsl, scene_bindings.glsl and textures.glsl. In a fragment shader textures
// are sampled with the implicit derivatives; a compute shader defines SURFACE_GRADIENTS and
// sets surface_uv_dx and surface_uv_dy (∂uv/∂x, ∂uv/∂y at the pixel) before surface_at.

#ifndef MANYLIGHTS_SURFACE_GLSL
#define MANYLIGHTS_SURFACE_GLSL

#include "common/shading_model.glsl"

// What an 8-bit unit normal's rounding alone can take off its length (√3/255).
const float NORMAL_ROUNDING = 0.0068;

// Sample `t` at `uv`, whose texture coordinates are `m` times the surface's.
#ifdef SURFACE_GRADIENTS
vec2 surface_uv_dx;
vec2 surface_uv_dy;
#define SURFACE_SAMPLE(t, uv, m) textureGrad(t, uv, (m) * surface_uv_dx, (m) * surface_uv_dy)
#else
#define SURFACE_SAMPLE(t, uv, m) texture(t, uv)
#endif

// Set 2 of the mesh pipelines, bound per draw: the object's own textures (glTF), or white
// stand-ins where ObjectPush.ids.y says it has none (object_textures.rs). A set per draw,
// not an array indexed per draw: lavapipe has no dynamic indexing of sampler arrays.
layout(set = 2, binding = 0) uniform sampler2D object_base_color;         // sRGB
layout(set = 2, binding = 1) uniform sampler2D object_normal_map;         // n·0.5 + 0.5
layout(set = 2, binding = 2) uniform sampler2D object_metallic_roughness; // g: roughness, b: metallic
layout(set = 2, binding = 3) uniform sampler2D object_occlusion;          // r
layout(set = 2, binding = 4) uniform sampler2D object_emissive;           // sRGB
// glTF's PBR extensions' (LOBE_TEXTURES), each multiplying its factor.
layout(set = 2, binding = 5) uniform sampler2D object_clearcoat;           // r
layout(set = 2, binding = 6) uniform sampler2D object_clearcoat_roughness; // g
layout(set = 2, binding = 7) uniform sampler2D object_clearcoat_normal;    // n·0.5 + 0.5
layout(set = 2, binding = 8) uniform sampler2D object_sheen_color;         // sRGB
layout(set = 2, binding = 9) uniform sampler2D object_sheen_roughness;     // a
layout(set = 2, binding = 10) uniform sampler2D object_specular;           // a
layout(set = 2, binding = 11) uniform sampler2D object_specular_color;     // sRGB
layout(set = 2, binding = 12) uniform sampler2D object_transmission;       // r
layout(set = 2, binding = 13) uniform sampler2D object_thickness;          // g
// Bits of ObjectPush.ids.y (ObjectTextures::bits).
const uint TEXTURE_BASE_COLOR = 1u;
const uint TEXTURE_NORMAL = 2u;
const uint TEXTURE_METALLIC_ROUGHNESS = 4u;
const uint TEXTURE_OCCLUSION = 8u;
const uint TEXTURE_EMISSIVE = 16u;
const uint TEXTURE_CLEARCOAT = 32u;
const uint TEXTURE_CLEARCOAT_ROUGHNESS = 64u;
const uint TEXTURE_CLEARCOAT_NORMAL = 128u;
const uint TEXTURE_SHEEN_COLOR = 256u;
const uint TEXTURE_SHEEN_ROUGHNESS = 512u;
const uint TEXTURE_SPECULAR = 1024u;
const uint TEXTURE_SPECULAR_COLOR = 2048u;
const uint TEXTURE_TRANSMISSION = 4096u;
const uint TEXTURE_THICKNESS = 8192u;

// What the textures make of the object's material: factors that multiply its own values.
struct Surface {
    vec3 normal;                // unit, world space
    vec3 albedo_factor;         // multiplies the object's albedo
    vec2 roughness_metallic;    // multiply its roughness and metallic
    float occlusion;            // of ambient light (1: none)
    vec3 emissive_factor;       // multiplies its emissive factor
    // How far the normals a filtered normal-map texel averages spread (normal_spread),
    // in 1/255 steps as the G-buffer and the transparent layers keep it; 0 without a map.
    float normal_spread;
    // The extensions' textures at the point and the clear coat's normal (LOBE_TEXTURES).
    LobeTexels lobes;
};

// `n` perturbed by a tangent-space normal-map texel (n·0.5 + 0.5 encoded), its x and y
// scaled by `scale` (glTF's normalTexture.scale).
vec3 perturb_normal(vec3 n, vec4 tangent, vec3 texel, float scale) {
    vec3 t = normalize(tangent.xyz - dot(tangent.xyz, n) * n);
    vec3 b = tangent.w * cross(n, t);
    vec3 m = (texel * 2.0 - 1.0) * vec3(scale, scale, 1.0);
    return normalize(m.x * t + m.y * b + m.z * n);
}

// How far the normals under a filtered normal-map texel spread: the mean of unit vectors is
// the shorter the more they differ, and its length |m| gives the variance of their slopes,
// (1 − |m|) / |m| (Toksvig 2005). Far away or at a grazing angle a texel's mip level averages
// bumps a pixel cannot show, and where the unfiltered map would sparkle, the lighting widens
// the highlight by this much instead (point_material) — as a supersampled image averages the
// sparkles. Less than 8-bit texels' own rounding (a unit vector's length is off by up to
// √3/255) counts as none. The standard deviation, in the 1/255 steps the G-buffer keeps it,
// so that every technique lights the same value; the normal map's scale scales the slopes.
float normal_spread(vec3 texel, float scale) {
    float len = length(texel * 2.0 - 1.0);
    float variance = max((1.0 - len) / max(len, 1e-4) - NORMAL_ROUNDING, 0.0) * scale * scale;
    return round(min(sqrt(variance), 1.0) * 255.0) / 255.0;
}

// `textures`: which textures the object has of its own (TEXTURE_* bits); `material`: its
// ObjectData.material (y: occlusion strength, z: normal scale); `object`: its index (whose
// clear coat normal scale a coat normal map reads).
Surface surface_at(vec3 geometric_normal, vec4 tangent, vec2 uv, uint textures, vec4 material, uint object) {
    Surface s;
    s.normal = normalize(geometric_normal);
    s.lobes = no_lobe_texels(s.normal);
    if (LOBE_TEXTURES) {
        // The object's texture `t` where bit `bit` says it has one, else white (1: the factor
        // as it is).
#define LOBE_TEXEL(bit, t) ((textures & (bit)) != 0u ? SURFACE_SAMPLE(t, uv, mat2(1.0)) : vec4(1.0))
        s.lobes.coat = vec2(LOBE_TEXEL(TEXTURE_CLEARCOAT, object_clearcoat).r, LOBE_TEXEL(TEXTURE_CLEARCOAT_ROUGHNESS, object_clearcoat_roughness).g);
        if ((textures & TEXTURE_CLEARCOAT_NORMAL) != 0u) {
            vec3 texel = SURFACE_SAMPLE(object_clearcoat_normal, uv, mat2(1.0)).xyz;
            s.lobes.coat_normal = perturb_normal(s.normal, tangent, texel, objects[object].lobes[3].w);
        }
        s.lobes.sheen = vec4(LOBE_TEXEL(TEXTURE_SHEEN_COLOR, object_sheen_color).rgb, LOBE_TEXEL(TEXTURE_SHEEN_ROUGHNESS, object_sheen_roughness).a);
        s.lobes.specular = vec4(LOBE_TEXEL(TEXTURE_SPECULAR_COLOR, object_specular_color).rgb, LOBE_TEXEL(TEXTURE_SPECULAR, object_specular).a);
        s.lobes.transmission =
            vec2(LOBE_TEXEL(TEXTURE_TRANSMISSION, object_transmission).r, LOBE_TEXEL(TEXTURE_THICKNESS, object_thickness).g);
#undef LOBE_TEXEL
    }
    s.albedo_factor = vec3(1.0);
    s.roughness_metallic = vec2(1.0);
    s.occlusion = 1.0;
    s.emissive_factor = vec3(1.0);
    s.normal_spread = 0.0;
    if (OBJECT_TEXTURES) {
        if ((textures & TEXTURE_BASE_COLOR) != 0u) {
            s.albedo_factor = SURFACE_SAMPLE(object_base_color, uv, mat2(1.0)).rgb;
        }
        if ((textures & TEXTURE_NORMAL) != 0u) {
            vec3 texel = SURFACE_SAMPLE(object_normal_map, uv, mat2(1.0)).xyz;
            s.normal = perturb_normal(s.normal, tangent, texel, material.z);
            if (SPECULAR_AA) {
                s.normal_spread = normal_spread(texel, material.z);
            }
        }
        if ((textures & TEXTURE_METALLIC_ROUGHNESS) != 0u) {
            s.roughness_metallic = SURFACE_SAMPLE(object_metallic_roughness, uv, mat2(1.0)).gb;
        }
        if ((textures & TEXTURE_OCCLUSION) != 0u) {
            s.occlusion = 1.0 + material.y * (SURFACE_SAMPLE(object_occlusion, uv, mat2(1.0)).r - 1.0);
        }
        if ((textures & TEXTURE_EMISSIVE) != 0u) {
            s.emissive_factor = SURFACE_SAMPLE(object_emissive, uv, mat2(1.0)).rgb;
        }
    }
    if (MODEL_BLINN_PHONG) {
        // Through opaque_uniform: lavapipe's fragment shaders read a storage buffer as 0 in the
        // lanes of a quad outside the triangle, which would spoil the derivatives of `st`.
        vec4 t = opaque_uniform(frame.texture_transform);
        mat2 st_transform = mat2(t.xy, t.zw);
        vec2 st = st_transform * uv;
        s.albedo_factor *= SURFACE_SAMPLE(albedo_map, st, st_transform).rgb;
        s.normal = perturb_normal(s.normal, tangent, SURFACE_SAMPLE(normal_map, st, st_transform).xyz, 1.0);
    }
    return s;
}

#endif
