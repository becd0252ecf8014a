// Fragment shader of the forward techniques. `forward.frag` loops over every light;
// `clustered.frag` defines CLUSTERED and loops over its cluster's lights only, `forward_grid.frag`
// defines LIGHT_GRID and loops over the light grid's lights near the point. Everything
// else — inputs, BRDF, summation order (ascending light index) — is shared (lighting.glsl),
// so the two give the same image when culling is correct.

#include "common/common.glsl"

#include "shading/mesh_fragment_inputs.glsl"
#include "common/scene_bindings.glsl"

#include "common/textures.glsl"
#include "common/surface.glsl"
// Before the light loop: its shadow rays read the alpha masks at this shader's binding.
#include "shading/mesh_coverage.glsl"
#include "common/lighting.glsl"
#include "shading/display_output.glsl"

layout(location = 0) out vec4 out_color;

// The scene has transparent layers (transparency/layers.glsl): the pass writes linear HDR
// colour (alpha 1 where a surface is; the clear leaves 0), which the transparent resolve
// blends the layers over and encodes.
layout(constant_id = 40) const bool TRANSPARENT_LAYERS = false;

void main() {
    MeshPoint at = covered_point();
#if defined(CLUSTERED) || defined(LIGHT_GRID)
    if (frame.viewport.z == DEBUG_VIEW_CLUSTER_HEAT) {
        // Lights tested on a log scale up to cluster_slices.z.
        uint count = cluster_light_count(at.world, gl_FragCoord.xy);
        float t = log2(1.0 + float(count)) / log2(1.0 + frame.cluster_slices.z);
        out_color = target_stored(heat(t));
        return;
    }
#endif
    Surface s = surface_at(at.normal, at.tangent, at.uv, opaque_uniform(object.ids.y), object.material, object.ids.x);
    PointMaterial m = point_material(object.albedo_roughness, object.material, object.emissive, vec4(s.albedo_factor, s.occlusion),
                                     s.roughness_metallic, s.emissive_factor, s.normal_spread, object.ids.x, s.lobes);
    vec3 color;
    if (debug_surface(at.world, s.normal, m.albedo, m.roughness, m.metallic, objects[object.ids.x].alpha_texture.x, gl_FragCoord.xy, color)) {
        out_color = target_shown(color);
        return;
    }
    color = shade_point(at.world, s.normal, m, gl_FragCoord.xy);
    if (ray_cost_shown(color)) {
        out_color = target_shown(color);
        return;
    }
    // The target is UNORM: the seed writes gamma-encoded values itself (or, anti-aliased, the
    // display's linear light, display_output.glsl).
    out_color = TRANSPARENT_LAYERS ? vec4(color, 1.0) : target_lit(color, frame.exposure.x);
}
