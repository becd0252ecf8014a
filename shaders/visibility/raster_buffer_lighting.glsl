// Lighting from the visibility buffer (visibility_lighting.glsl) as the compute raster left
// it: depth and id per pixel in one 64-bit buffer, read where it lies.
#define LIGHT_GRID 1
#define SURFACE_GRADIENTS 1
#include "common/common.glsl"
#include "common/scene_bindings.glsl"

// Per pixel: x: the visibility id; y: the depth's bits (all ones: nothing drawn).
layout(std430, set = 0, binding = 5) readonly buffer VisibilityDepthBuffer { uvec2 visibility_depth[]; };

float raster_depth(ivec2 pixel) {
    return visibility_buffer_depth(visibility_depth[uint(pixel.y) * frame.viewport.x + uint(pixel.x)]);
}

uint raster_id(ivec2 pixel) {
    return visibility_buffer_id(visibility_depth[uint(pixel.y) * frame.viewport.x + uint(pixel.x)]);
}

#include "visibility/visibility_lighting.glsl"
