#version 450
#extension GL_GOOGLE_include_directive : require
// The depth pyramid (depth_pyramid_pass.glsl) from the compute raster's 64-bit buffer, read
// where it lies: no image is made of it. A pixel's depth is the farthest of its samples.
#include "common/common.glsl"
#include "visibility/visibility_samples.glsl"

// Per sample: x: the visibility id; y: the depth's bits (all ones: nothing drawn).
layout(std430, set = 0, binding = 0) readonly buffer VisibilityDepthBuffer { uvec2 visibility_depth[]; };

float raster_depth(uvec2 pixel, uint width) {
    float farthest = 0.0;
    [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
        farthest = max(farthest, visibility_buffer_depth(visibility_depth[sample_slot(ivec2(pixel), k, width)]));
    }
    return farthest;
}

#include "visibility/depth_pyramid_pass.glsl"
