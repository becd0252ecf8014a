// Subpass 1 of the deferred render pass (docs/DESIGN.md#deferred-shading-in-one-render-pass):
// reads the G-buffer that subpass 0 wrote as input attachments (this pixel only: subpassLoad),
// rebuilds the position from depth and shades it with lighting.glsl into the HDR target.
// `deferred.frag` loops over every light, `deferred_clustered.frag` over the fragment's
// cluster. Pixels no object covers keep the clear value (alpha 0), which the tone-map pass
// turns into the background colour.

#include "common/common.glsl"

#include "common/scene_bindings.glsl"
#include "common/textures.glsl"
// MULTISAMPLED (the *_samples.frag variants): anti-aliasing. Subpass 0 drew into multisampled
// attachments; this pixel's samples are grouped by surface (equal G-buffer values: one
// fragment of subpass 0 wrote them), each surface shaded once at the mean of its samples'
// points, and the pixel written as the mean of its samples in the display's linear light
// (display_output.glsl), with the covered share in alpha for the tone map's background.
#ifdef MULTISAMPLED
#define INPUT subpassInputMS
#define UINPUT usubpassInputMS
#define LOAD(input, s) subpassLoad(input, s)
#else
#define INPUT subpassInput
#define UINPUT usubpassInput
#define LOAD(input, s) subpassLoad(input)
#endif
layout(input_attachment_index = 0, set = 2, binding = 1) uniform INPUT depth_input;
layout(input_attachment_index = 1, set = 2, binding = 2) uniform INPUT normal_input;
layout(input_attachment_index = 2, set = 2, binding = 3) uniform UINPUT object_input;
layout(input_attachment_index = 3, set = 2, binding = 4) uniform INPUT albedo_input;
// GBUFFER_MATERIAL (the *_textured.frag variants): scenes whose objects have textures of their
// own, whose G-buffer has two more images (targets.rs gbuffer_images). A variant, not a
// specialization constant: a subpass may not even declare inputs it lacks.
#ifdef GBUFFER_MATERIAL
layout(input_attachment_index = 4, set = 2, binding = 5) uniform INPUT roughness_metallic_input;
layout(input_attachment_index = 5, set = 2, binding = 6) uniform INPUT emissive_input;
#endif
// GBUFFER_LOBES (the *_lobes.frag variants): where the PBR extensions vary per point, one
// more image (a subpass reads at most 8 input attachments on lavapipe: the texels packed).
#ifdef GBUFFER_LOBES
layout(input_attachment_index = 6, set = 2, binding = 7) uniform UINPUT lobes_input;
#endif

#include "common/lighting.glsl"
// For every variant (the reflection test reads includes whole): the samples' count and
// positions, which the multisampled one reads.
#include "visibility/visibility_samples.glsl"

layout(location = 0) out vec4 out_hdr;

#define GBUFFER_LOAD(name, s) LOAD(name##_input, s)
#include "shading/gbuffer_samples.glsl"

// The surface `g` at `frag_xy` (pixels) and depth `z`, lit; `debug`: a surface debug view's
// colour, shown as it is.
vec3 shade_gbuffer(vec2 frag_xy, float z, GSample g, out bool debug) {
    vec3 world = world_from_depth(frag_xy, z);
    vec3 n = oct_decode(g.normal);
    PointMaterial m = point_material(objects[g.id].albedo_roughness, objects[g.id].material, objects[g.id].emissive, g.albedo,
                                     g.roughness_metallic, g.emissive_factor, g.normal_spread, g.id, gsample_lobes(g));
    vec3 color;
    debug = debug_surface(world, n, m.albedo, m.roughness, m.metallic, objects[g.id].alpha_texture.x, frag_xy, color);
    if (!debug) {
        color = shade_point(world, n, m, frag_xy);
        debug = ray_cost_shown(color);
    }
    return color;
}

vec3 surface_display(vec2 xy, float z, GSample g) {
    bool debug;
    vec3 color = shade_gbuffer(xy, z, g, debug);
    return debug ? clamp(color, 0.0, 1.0) : display_linear(color, frame.exposure.x);
}

#ifdef MULTISAMPLED
void main() {
    vec4 resolved = resolve_samples(ivec2(gl_FragCoord.xy));
    if (resolved.a == 0.0) {
        discard;
    }
    out_hdr = resolved;
}
#else
void main() {
    float z = LOAD(depth_input, 0).r;
    if (z >= 1.0) {
        discard;
    }
    bool debug;
    out_hdr = vec4(shade_gbuffer(gl_FragCoord.xy, z, gbuffer_sample(0), debug), 1.0);
}
#endif
