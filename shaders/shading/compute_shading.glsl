// The end of both compute lighting passes (deferred_lighting.comp from the G-buffer,
// visibility_lighting.comp from the visibility buffer): a surface point shaded — or shown
// by a surface debug view — and stored. Needs lighting.glsl and `out_image`.

#ifndef MANYLIGHTS_COMPUTE_SHADING_GLSL
#define MANYLIGHTS_COMPUTE_SHADING_GLSL

// `object_flags`: the object's OBJECT_* bits (the alpha debug view).
void shade_and_store(ivec2 p, vec2 frag_xy, vec3 world, vec3 n, PointMaterial m, uint object_flags) {
    vec3 color;
    if (debug_surface(world, n, m.albedo, m.roughness, m.metallic, object_flags, color)) {
        imageStore(out_image, p, vec4(encode_gamma(color), 1.0));
        return;
    }
    color = shade_point(world, n, m.albedo, m.roughness, m.metallic, m.occlusion, m.emission, frag_xy);
    imageStore(out_image, p, vec4(encode_output(color, frame.exposure.x), 1.0));
}

#endif
