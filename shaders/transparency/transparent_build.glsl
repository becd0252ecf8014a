// The transparent objects' fragments in front of the opaque surfaces, kept as nodes of their
// pixel's list (layers.glsl): depth, coverage — the base colour's alpha factor times its
// texture's alpha — and the surface the G-buffer would hold, unlit. No attachments: the
// opaque depth is read and compared here (a depth image, or the compute raster's 64-bit
// visibility-depth buffer), and nothing is written but the lists.
#include "common/common.glsl"

#include "shading/mesh_fragment_inputs.glsl"
#include "common/scene_bindings.glsl"
#include "common/textures.glsl"
#include "common/surface.glsl"
#include "shading/mesh_coverage.glsl"

#define LAYER_BINDING 14
#include "transparency/layers.glsl"

// The opaque depth: the raster's depth image, or (OPAQUE_DEPTH_BUFFER) the compute raster's
// 64-bit buffer (depth in the high word).
#ifdef OPAQUE_DEPTH_BUFFER
layout(std430, set = 0, binding = 13) readonly buffer VisibilityDepthBuffer { uvec2 visibility_depth[]; };
float opaque_depth_at(ivec2 p) {
    return visibility_buffer_depth(visibility_depth[layer_pixel(p)]);
}
#else
layout(set = 0, binding = 12) uniform sampler2D opaque_depth;
float opaque_depth_at(ivec2 p) {
    return texelFetch(opaque_depth, p, 0).r;
}
#endif

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    if (gl_FragCoord.z >= opaque_depth_at(p)) {
        return;
    }
    uint o = object.ids.x;
    float alpha = objects[o].alpha.y;
    if ((objects[o].alpha_texture.x & OBJECT_ALPHA_TEXTURE) != 0u) {
        alpha *= texture_alpha(objects[o].alpha_texture, in_uv);
    }
    if (alpha <= 0.0) {
        return;
    }
    Surface s = surface_at(covered_normal(), in_tangent, in_uv, object.ids.y, object.material);
    uvec4 surface = pack_layer_surface(s.normal, vec4(s.albedo_factor, s.occlusion), s.roughness_metallic, min(alpha, 1.0), s.emissive_factor);
    store_layer(p, gl_FragCoord.z, o, surface);
}
