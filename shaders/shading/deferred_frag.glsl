// Subpass 1 of the deferred render pass (docs/DESIGN.md#deferred-shading-in-one-render-pass):
// reads the G-buffer that subpass 0 wrote as input attachments (this pixel only: subpassLoad),
// rebuilds the position from depth and shades it with lighting.glsl into the HDR target.
// `deferred.frag` loops over every light, `deferred_clustered.frag` over the fragment's
// cluster. Pixels no object covers keep the clear value (alpha 0), which the tone-map pass
// turns into the background colour.

#include "common/common.glsl"

#include "common/scene_bindings.glsl"
#include "common/textures.glsl"
layout(input_attachment_index = 0, set = 2, binding = 1) uniform subpassInput depth_input;
layout(input_attachment_index = 1, set = 2, binding = 2) uniform subpassInput normal_input;
layout(input_attachment_index = 2, set = 2, binding = 3) uniform usubpassInput object_input;
layout(input_attachment_index = 3, set = 2, binding = 4) uniform subpassInput albedo_input;
// GBUFFER_MATERIAL (the *_textured.frag variants): scenes whose objects have textures of their
// own, whose G-buffer has two more images (targets.rs gbuffer_images). A variant, not a
// specialization constant: a subpass may not even declare inputs it lacks.
#ifdef GBUFFER_MATERIAL
layout(input_attachment_index = 4, set = 2, binding = 5) uniform subpassInput roughness_metallic_input;
layout(input_attachment_index = 5, set = 2, binding = 6) uniform subpassInput emissive_input;
#endif

#include "common/lighting.glsl"

layout(location = 0) out vec4 out_hdr;

void main() {
    float z = subpassLoad(depth_input).r;
    if (z >= 1.0) {
        discard;
    }
    vec3 world = world_from_depth(gl_FragCoord.xy, z);
    vec3 n = oct_decode(subpassLoad(normal_input).xy);
    uint id = subpassLoad(object_input).r;
#ifdef GBUFFER_MATERIAL
    vec2 roughness_metallic = subpassLoad(roughness_metallic_input).xy;
    vec3 emissive_factor = subpassLoad(emissive_input).rgb;
#else
    vec2 roughness_metallic = vec2(1.0);
    vec3 emissive_factor = vec3(1.0);
#endif
    PointMaterial m =
        point_material(objects[id].albedo_roughness, objects[id].material, objects[id].emissive, subpassLoad(albedo_input), roughness_metallic, emissive_factor);
    vec3 color;
    if (!debug_surface(world, n, m.albedo, m.roughness, m.metallic, objects[id].alpha_texture.x, gl_FragCoord.xy, color)) {
        color = shade_point(world, n, m.albedo, m.roughness, m.metallic, m.occlusion, m.emission, gl_FragCoord.xy);
    }
    out_hdr = vec4(color, 1.0);
}
