// What the transparent layers' builds test their fragments against (transparent_build.glsl,
// transparent_build_compute.glsl). Needs layers.glsl (layer_pixel) and common.glsl.

#ifndef MANYLIGHTS_OPAQUE_DEPTH_GLSL
#define MANYLIGHTS_OPAQUE_DEPTH_GLSL

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

#endif
