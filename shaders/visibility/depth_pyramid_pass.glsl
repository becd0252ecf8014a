// The depth pyramid's level 0 (depth_pyramid.glsl): the early raster's depth reduced 2×2 to
// the farthest depth (pixels beyond the image count as the nearest depth, 0, so they never
// hide anything); depth_pyramid_levels.comp makes the levels above. The includer says where
// the raster's depth is: `float raster_depth(uvec2 pixel, uint width)` (depth_pyramid.comp:
// the hardware raster's depth image; depth_pyramid_buffer.comp: the compute raster's 64-bit
// buffer), or with GROUP_FARTHEST `float group_farthest(uvec2 texel, uvec2 image)`, which the
// whole work group calls (depth_pyramid_samples.comp: the buffer's samples).

#ifndef MANYLIGHTS_DEPTH_PYRAMID_PASS_GLSL
#define MANYLIGHTS_DEPTH_PYRAMID_PASS_GLSL

#include "common/common.glsl"
#include "visibility/depth_pyramid.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std430, set = 0, binding = 1) buffer DepthPyramidBuffer { float depth_pyramid[]; };
layout(push_constant) uniform PyramidPushBlock { uvec4 image_size; }; // xy: the image's size

void main() {
    uvec2 image = image_size.xy;
    uvec2 size = pyramid_level_size(image, 0);
    uvec2 p = gl_GlobalInvocationID.xy;
#ifdef GROUP_FARTHEST
    // The whole work group reads its pixels together (barriers): every thread takes part.
    float farthest = group_farthest(p, image);
    if (any(greaterThanEqual(p, size))) {
        return;
    }
#else
    if (any(greaterThanEqual(p, size))) {
        return;
    }
    float farthest = 0.0;
    for (uint i = 0u; i < 4u; i++) {
        uvec2 q = 2u * p + uvec2(i & 1u, i >> 1u);
        if (all(lessThan(q, image))) {
            farthest = max(farthest, raster_depth(q, image.x));
        }
    }
#endif
    depth_pyramid[p.y * size.x + p.x] = farthest;
}

#endif
