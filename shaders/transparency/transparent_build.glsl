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

#include "common/opaque_depth.glsl"

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    uint o = object.ids.x;
    // The textures first, sampled with their implicit derivatives while the whole quad still
    // runs (after a fragment of it returns they are undefined); and every read this fragment
    // needs issued together, before the test that waits on the opaque depth.
    MeshPoint at = covered_point();
    Surface s = surface_at(at.normal, at.tangent, at.uv, opaque_uniform(object.ids.y), object.material);
    float alpha = objects[o].alpha.y;
    uvec4 alpha_texture = objects[o].alpha_texture;
    float opaque = opaque_depth_at(p);
    if ((alpha_texture.x & OBJECT_ALPHA_TEXTURE) != 0u) {
        alpha *= texture_alpha(alpha_texture, at.uv);
    }
    if (gl_FragCoord.z >= opaque || alpha <= 0.0) {
        return;
    }
    uvec4 surface = pack_layer_surface(s.normal, vec4(s.albedo_factor, s.occlusion), s.roughness_metallic, min(alpha, 1.0), s.emissive_factor);
    store_layer(p, gl_FragCoord.z, o, surface);
}
