// Lighting from the visibility buffer (visibility_lighting.glsl) as the hardware raster left
// it: a depth image and an image of ids.
#define LIGHT_GRID 1
#define SURFACE_GRADIENTS 1
#include "common/common.glsl"
#include "common/scene_bindings.glsl"

layout(set = 0, binding = 5) uniform sampler2D depth_image;
layout(set = 0, binding = 6) uniform usampler2D visibility_image;

float raster_depth(ivec2 pixel) {
    return texelFetch(depth_image, pixel, 0).r;
}

uint raster_id(ivec2 pixel) {
    return texelFetch(visibility_image, pixel, 0).r;
}

#include "visibility/visibility_lighting.glsl"
