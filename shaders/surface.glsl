// What the rasterised surface contributes before lighting (forward fragment shaders and the
// G-buffer pass alike): an object's own base-colour texture and normal map (glTF), and
// blinn-phong's albedo texture and normal map; normal maps perturb the normal through the
// tangent frame (TBN). The seed model's built-in objects use none.
// Needs common.glsl, scene_bindings.glsl and textures.glsl. Fragment stage (implicit LOD).

#ifndef MANYLIGHTS_SURFACE_GLSL
#define MANYLIGHTS_SURFACE_GLSL

#include "shading_model.glsl"

// Set 2 of the mesh pipelines, bound per draw: the object's own textures (glTF), or white
// stand-ins where ObjectPush.ids says it has none (object_textures.rs). A set per draw,
// not an array indexed per draw: lavapipe has no dynamic indexing of sampler arrays.
// OBJECT_TEXTURES (a specialization constant): whether the scene has such textures at all; with
// the runtime test alone the seed scene's G-buffer pass took 1.90 ms instead of 1.55 and its
// forward pass at 64 lights 11.1 ms instead of 10.2 on the H100 (measured).
layout(constant_id = 13) const bool OBJECT_TEXTURES = false;
layout(set = 2, binding = 0) uniform sampler2D object_base_color;
layout(set = 2, binding = 1) uniform sampler2D object_normal_map;

struct Surface {
    vec3 normal;         // unit, world space
    vec3 albedo_factor;  // multiplies the object's albedo
};

// `n` perturbed by a tangent-space normal-map texel (n·0.5 + 0.5 encoded).
vec3 perturb_normal(vec3 n, vec4 tangent, vec3 texel) {
    vec3 t = normalize(tangent.xyz - dot(tangent.xyz, n) * n);
    vec3 b = tangent.w * cross(n, t);
    vec3 m = texel * 2.0 - 1.0;
    return normalize(m.x * t + m.y * b + m.z * n);
}

// `textures`: whether the object has its own base-colour texture (x) and normal map (y).
Surface surface_at(vec3 geometric_normal, vec4 tangent, vec2 uv, uvec2 textures) {
    Surface s;
    s.normal = normalize(geometric_normal);
    s.albedo_factor = vec3(1.0);
    if (OBJECT_TEXTURES && textures.x != 0u) {
        s.albedo_factor = texture(object_base_color, uv).rgb;
    }
    if (OBJECT_TEXTURES && textures.y != 0u) {
        s.normal = perturb_normal(s.normal, tangent, texture(object_normal_map, uv).xyz);
    }
    if (MODEL_BLINN_PHONG) {
        vec2 st = mat2(frame.texture_transform.xy, frame.texture_transform.zw) * uv;
        s.albedo_factor *= texture(albedo_map, st).rgb;
        s.normal = perturb_normal(s.normal, tangent, texture(normal_map, st).xyz);
    }
    return s;
}

#endif
