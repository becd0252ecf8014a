// The opaque surfaces' depth at a pixel, for compute and fragment passes that run after the
// opaque raster and test against it or rebuild positions from it (the transparent layers'
// builds, the light counts). Needs common.glsl (FrameBlock bound as `frame`).

#ifndef MANYLIGHTS_OPAQUE_DEPTH_GLSL
#define MANYLIGHTS_OPAQUE_DEPTH_GLSL

// The opaque depth: the raster's depth image, or (OPAQUE_DEPTH_BUFFER) the compute raster's
// 64-bit buffer (depth in the high word). 1 where nothing was drawn.
// (The samples' header for every includer: declared, its constant is left at one where no
// buffer is read.)
#include "visibility/visibility_samples.glsl"
#ifdef OPAQUE_DEPTH_BUFFER
layout(std430, set = 0, binding = 13) readonly buffer VisibilityDepthBuffer { uvec2 visibility_depth[]; };
// Sample k of pixel p as the compute raster left it (visibility_samples.glsl).
uvec2 opaque_sample(ivec2 p, uint k) {
    return visibility_depth[sample_slot(p, k, frame.viewport.x)];
}
// Sample k's depth.
float opaque_depth_of_sample(ivec2 p, uint k) {
    return visibility_buffer_depth(opaque_sample(p, k));
}
// With anti-aliasing, the first sample's.
float opaque_depth_at(ivec2 p) {
    return opaque_depth_of_sample(p, 0u);
}
#else
layout(set = 0, binding = 12) uniform sampler2D opaque_depth;
float opaque_depth_at(ivec2 p) {
    return texelFetch(opaque_depth, p, 0).r;
}
// One sample (no anti-aliasing here): the centre's.
float opaque_depth_of_sample(ivec2 p, uint k) {
    return opaque_depth_at(p);
}
#endif

#endif
