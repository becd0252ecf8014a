// Lighting from the visibility buffer (visibility_lighting.glsl) as the compute raster left
// it: depth and id per pixel in one 64-bit buffer, read where it lies.
#define LIGHT_GRID 1
#define SURFACE_GRADIENTS 1
#include "common/common.glsl"
#include "common/scene_bindings.glsl"

#include "visibility/visibility_samples.glsl"

// Per sample: x: the visibility id; y: the depth's bits (all ones: nothing drawn).
layout(std430, set = 0, binding = 5) readonly buffer VisibilityDepthBuffer { uvec2 visibility_depth[]; };

// Anti-aliasing's samples are read here (visibility_lighting.glsl shade_samples).
#define RASTER_SAMPLES 1

uvec2 raster_sample(ivec2 pixel, uint k) {
    return visibility_depth[sample_slot(pixel, k, frame.viewport.x)];
}

float raster_depth(ivec2 pixel) {
    return visibility_buffer_depth(raster_sample(pixel, 0u));
}

uint raster_id(ivec2 pixel) {
    return visibility_buffer_id(raster_sample(pixel, 0u));
}

#include "visibility/visibility_lighting.glsl"
