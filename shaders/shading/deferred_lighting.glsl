// deferred-compute: the lighting of lighting.glsl over the light grid as a compute shader over
// the G-buffer (on H100/H200 compute runs on all SMs, fragment shading on 4 of 132). Same BRDF
// and light loop as the fragment paths; position rebuilt from depth.
// The includer (deferred_lighting.comp, deferred_lighting_linear.comp) says what it writes.
#define LIGHT_GRID 1
#include "common/common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

#include "common/scene_bindings.glsl"
// MULTISAMPLED (deferred_lighting_samples.comp): anti-aliasing, the G-buffer multisampled and
// each pixel resolved from its samples (gbuffer_samples.glsl).
#ifdef MULTISAMPLED
#define IMAGE sampler2DMS
#define UIMAGE usampler2DMS
#else
#define IMAGE sampler2D
#define UIMAGE usampler2D
#endif
layout(set = 0, binding = 5) uniform IMAGE depth_image;
layout(set = 0, binding = 6) uniform IMAGE normal_image;
layout(set = 0, binding = 7) uniform UIMAGE object_image;
layout(set = 0, binding = 9) uniform IMAGE albedo_image;
layout(set = 0, binding = 11) uniform IMAGE roughness_metallic_image;
layout(set = 0, binding = 12) uniform IMAGE emissive_image;
// Read where the PBR extensions vary per point (LOBE_TEXTURES; else a stand-in never read).
layout(set = 0, binding = 36) uniform UIMAGE lobes_image;
#include "common/textures.glsl"

#include "common/lighting.glsl"
#include "shading/compute_shading.glsl"

// For every variant (the reflection test reads includes whole): the samples' count and
// positions, which the multisampled one reads.
#include "visibility/visibility_samples.glsl"

#ifdef MULTISAMPLED
// This invocation's pixel, whose samples GBUFFER_LOAD reads.
ivec2 gbuffer_pixel;
#define GBUFFER_LOAD(name, s) texelFetch(name##_image, gbuffer_pixel, s)
// Without OBJECT_TEXTURES the material and emissive images are stand-ins, never read, and
// without LOBE_TEXTURES the lobes' images.
#define GBUFFER_MATERIAL 1
#define GBUFFER_LOBES 1
#include "shading/gbuffer_samples.glsl"

vec3 surface_display(vec2 xy, float z, GSample g) {
    vec2 roughness_metallic = OBJECT_TEXTURES ? g.roughness_metallic : vec2(1.0);
    vec3 emissive_factor = OBJECT_TEXTURES ? g.emissive_factor : vec3(1.0);
    float normal_spread = OBJECT_TEXTURES ? g.normal_spread : 0.0;
    PointMaterial m = point_material(objects[g.id].albedo_roughness, objects[g.id].material, objects[g.id].emissive, g.albedo,
                                     roughness_metallic, emissive_factor, normal_spread, g.id, gsample_lobes(g));
    return shade_display(xy, world_from_depth(xy, z), oct_decode(g.normal), m, objects[g.id].alpha_texture.x);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) {
        return;
    }
    gbuffer_pixel = p;
    vec4 resolved = resolve_samples(p);
    imageStore(out_image, p, vec4(encode_over_background(resolved.rgb, 1.0 - resolved.a, background_linear(p)), 1.0));
}
#else
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) {
        return;
    }
    float z = texelFetch(depth_image, p, 0).r;
    if (z >= 1.0) {
        store_background(p);
        return;
    }
    vec2 frag_xy = vec2(p) + 0.5;
    vec3 world = world_from_depth(frag_xy, z);
    vec3 n = oct_decode(texelFetch(normal_image, p, 0).xy);
    uint id = texelFetch(object_image, p, 0).r;
    // Without OBJECT_TEXTURES the G-buffer has no material and emissive images (the pass
    // binds stand-ins that are never read).
    vec2 roughness_metallic = OBJECT_TEXTURES ? texelFetch(roughness_metallic_image, p, 0).xy : vec2(1.0);
    vec4 emissive = OBJECT_TEXTURES ? texelFetch(emissive_image, p, 0) : vec4(1.0, 1.0, 1.0, 0.0);
    LobeTexels lobes = LOBE_TEXTURES ? unpack_lobe_texels(texelFetch(lobes_image, p, 0)) : no_lobe_texels(n);
    PointMaterial m = point_material(objects[id].albedo_roughness, objects[id].material, objects[id].emissive, texelFetch(albedo_image, p, 0),
                                     roughness_metallic, emissive.rgb, emissive.a, id, lobes);
    shade_and_store(p, frag_xy, world, n, m, objects[id].alpha_texture.x);
}
#endif
