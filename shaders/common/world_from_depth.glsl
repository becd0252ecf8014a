// World position of a pixel from its depth (the deferred and visibility lighting, the light
// counts, the light grid's marks: one function, so that every pass finds the same point).
// Needs `frame` (FrameBlock).

#ifndef MANYLIGHTS_WORLD_FROM_DEPTH_GLSL
#define MANYLIGHTS_WORLD_FROM_DEPTH_GLSL

// World position of the pixel centre `frag_xy` at depth-buffer value `z`.
vec3 world_from_depth(vec2 frag_xy, float z) {
    vec2 ndc = frag_xy / vec2(frame.viewport.xy) * 2.0 - 1.0;
    vec4 w = frame.inv_view_proj * vec4(ndc, z, 1.0);
    return w.xyz / w.w;
}

#endif
