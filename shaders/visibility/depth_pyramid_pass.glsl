// The depth pyramid of the late culling phase (depth_pyramid.glsl), one dispatch per level:
// level 0 reduces the early raster's depth 2×2 to the farthest depth (pixels beyond the image
// count as the nearest depth, 0, so they never hide anything), each further level the one
// before. The includer says where the raster's depth is: `float raster_depth(uvec2 pixel, uint width)`
// (depth_pyramid.comp: the hardware raster's depth image; depth_pyramid_buffer.comp: the
// compute raster's 64-bit buffer).

#ifndef MANYLIGHTS_DEPTH_PYRAMID_PASS_GLSL
#define MANYLIGHTS_DEPTH_PYRAMID_PASS_GLSL

#include "common/common.glsl"
#include "visibility/depth_pyramid.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std430, set = 0, binding = 1) buffer DepthPyramidBuffer { float depth_pyramid[]; };
layout(push_constant) uniform PyramidPushBlock { uvec4 level; }; // x: the level written; yz: image size

void main() {
    uvec2 image = level.yz;
    int l = int(opaque_uniform(level.x));
    uvec2 size = pyramid_level_size(image, l);
    uvec2 p = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(p, size))) {
        return;
    }
    float farthest = 0.0;
    if (l == 0) {
        for (uint i = 0u; i < 4u; i++) {
            uvec2 q = 2u * p + uvec2(i & 1u, i >> 1u);
            if (all(lessThan(q, image))) {
                farthest = max(farthest, raster_depth(q, image.x));
            }
        }
    } else {
        uvec2 below = pyramid_level_size(image, l - 1);
        uint base = pyramid_level_offset(image, l - 1);
        for (uint i = 0u; i < 4u; i++) {
            uvec2 q = min(2u * p + uvec2(i & 1u, i >> 1u), below - 1u);
            farthest = max(farthest, depth_pyramid[base + q.y * below.x + q.x]);
        }
    }
    depth_pyramid[pyramid_level_offset(image, l) + p.y * size.x + p.x] = farthest;
}

#endif
