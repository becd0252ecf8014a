#version 450
#extension GL_GOOGLE_include_directive : require
// The depth pyramid (depth_pyramid_pass.glsl) from the compute raster's 64-bit buffer, read
// where it lies: no image is made of it.
#include "common/common.glsl"

// Per pixel: x: the visibility id; y: the depth's bits (all ones: nothing drawn).
layout(std430, set = 0, binding = 0) readonly buffer VisibilityDepthBuffer { uvec2 visibility_depth[]; };

float raster_depth(uvec2 pixel, uint width) {
    return visibility_buffer_depth(visibility_depth[pixel.y * width + pixel.x]);
}

#include "visibility/depth_pyramid_pass.glsl"
