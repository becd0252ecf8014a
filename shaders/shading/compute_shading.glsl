// The end of both compute lighting passes (deferred_lighting.comp from the G-buffer,
// visibility_lighting.comp from the visibility buffer): a surface point shaded — or shown
// by a surface debug view — and stored. Needs lighting.glsl and `out_image`.

#ifndef MANYLIGHTS_COMPUTE_SHADING_GLSL
#define MANYLIGHTS_COMPUTE_SHADING_GLSL

// The transparent layers, blended where the pixel is shaded (TRANSPARENT_LAYERS).
#define LAYER_BINDING 20
#include "transparency/layers.glsl"

// `object_flags`: the object's OBJECT_* bits (the alpha debug view).
void shade_and_store(ivec2 p, vec2 frag_xy, vec3 world, vec3 n, PointMaterial m, uint object_flags) {
    vec3 color;
    if (debug_surface(world, n, m.albedo, m.roughness, m.metallic, object_flags, color)) {
        imageStore(out_image, p, vec4(encode_gamma(color), 1.0));
        return;
    }
    color = shade_point(world, n, m.albedo, m.roughness, m.metallic, m.occlusion, m.emission, frag_xy);
    imageStore(out_image, p, layered_output(p, frag_xy, color, false, frame.exposure.x));
}

// A pixel no opaque surface covers: the background, under the transparent layers.
void store_background(ivec2 p) {
    imageStore(out_image, p, layered_output(p, vec2(p) + 0.5, vec3(0.0), true, frame.exposure.x));
}

#endif
