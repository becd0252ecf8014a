// What the rasterised surface contributes before lighting (forward fragment shaders and the
// G-buffer pass alike): blinn-phong samples its albedo texture and perturbs the normal with
// the normal map through the tangent frame (TBN); the seed model uses neither.
// Needs common.glsl, scene_bindings.glsl and textures.glsl. Fragment stage (implicit LOD).

#ifndef MANYLIGHTS_SURFACE_GLSL
#define MANYLIGHTS_SURFACE_GLSL

#include "shading_model.glsl"

struct Surface {
    vec3 normal;         // unit, world space
    vec3 albedo_factor;  // multiplies the object's albedo
};

Surface surface_at(vec3 geometric_normal, vec4 tangent, vec2 uv) {
    Surface s;
    s.normal = normalize(geometric_normal);
    s.albedo_factor = vec3(1.0);
    if (MODEL_BLINN_PHONG) {
        vec2 st = mat2(frame.texture_transform.xy, frame.texture_transform.zw) * uv;
        s.albedo_factor = texture(albedo_map, st).rgb;
        vec3 t = normalize(tangent.xyz - dot(tangent.xyz, s.normal) * s.normal);
        vec3 b = tangent.w * cross(s.normal, t);
        vec3 m = texture(normal_map, st).xyz * 2.0 - 1.0;
        s.normal = normalize(m.x * t + m.y * b + m.z * s.normal);
    }
    return s;
}

#endif
