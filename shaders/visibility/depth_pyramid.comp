#version 450
#extension GL_GOOGLE_include_directive : require
// The depth pyramid (depth_pyramid_pass.glsl) from the hardware raster's depth image.

layout(set = 0, binding = 0) uniform sampler2D depth_image;

float raster_depth(uvec2 pixel, uint width) {
    return texelFetch(depth_image, ivec2(pixel), 0).r;
}

#include "visibility/depth_pyramid_pass.glsl"
