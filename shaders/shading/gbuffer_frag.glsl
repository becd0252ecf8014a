// G-buffer of the deferred techniques: 16 bytes per pixel besides depth — the normal
// (octahedral, two floats: exact enough that the seed's sharp highlights do not move), the
// object's index (its material comes from the object buffer at full precision) and the
// surface's albedo factor (the base-colour or blinn-phong texture; 1 for the seed model;
// sRGB-encoded by its image's format, so a texture's darks keep their steps) with the ambient
// occlusion in alpha — and, in scenes whose objects have textures of their own
// (GBUFFER_MATERIAL), 6 more: the roughness and metallic factors and the emissive factor;
// where their PBR extensions vary per point (GBUFFER_LOBES), 16 more: the extensions' texels
// and the clear coat's normal, packed (targets.rs). Position comes from depth.
#include "common/common.glsl"
#include "common/scene_bindings.glsl"
#include "common/textures.glsl"
#include "common/surface.glsl"

#include "shading/mesh_fragment_inputs.glsl"
#include "shading/mesh_coverage.glsl"

layout(location = 0) out vec2 out_normal;
layout(location = 1) out uint out_object;
layout(location = 2) out vec4 out_albedo_occlusion;
// GBUFFER_MATERIAL (gbuffer_textured.frag): scenes whose objects have textures of their own,
// whose G-buffer has these images too (targets.rs gbuffer_images).
#ifdef GBUFFER_MATERIAL
layout(location = 3) out vec2 out_roughness_metallic;
layout(location = 4) out vec4 out_emissive;
#endif
#ifdef GBUFFER_LOBES
layout(location = 5) out uvec4 out_lobes; // pack_lobe_texels
#endif

void main() {
    MeshPoint at = covered_point();
    Surface s = surface_at(at.normal, at.tangent, at.uv, opaque_uniform(object.ids.y), object.material, object.ids.x);
    out_normal = oct_encode(s.normal);
    out_object = object.ids.x;
    out_albedo_occlusion = vec4(s.albedo_factor, s.occlusion);
#ifdef GBUFFER_MATERIAL
    out_roughness_metallic = s.roughness_metallic;
    out_emissive = vec4(s.emissive_factor, s.normal_spread);
#endif
#ifdef GBUFFER_LOBES
    out_lobes = pack_lobe_texels(s.lobes);
#endif
}
