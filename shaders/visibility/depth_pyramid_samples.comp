#version 450
#extension GL_GOOGLE_include_directive : require
// The depth pyramid's level 0 (depth_pyramid_pass.glsl) from the compute raster's 64-bit
// buffer with anti-aliasing's samples (2 or more a pixel): a pixel's depth is the farthest of
// its samples. Read as the buffer lies, not a pixel a thread: a work group's 16×16 pixels are
// 16 runs of memory (a row's 16 pixels' samples each), and each step its threads read
// neighbouring pairs of samples, so that a subgroup's reads are one stretch of memory; each
// pair's farther depth goes to its pixel by a shared atomic maximum (the bits of non-negative
// floats order as the floats do). A thread per pixel read its samples 128 bytes from its
// neighbour's: on the H200, 0.084 ms for the bench scene's 1080p at 8 samples, 0.055 so.
#include "common/common.glsl"
#include "visibility/visibility_samples.glsl"

// Per sample: x: the visibility id; y: the depth's bits (all ones: nothing drawn).
layout(std430, set = 0, binding = 0) readonly buffer VisibilityDepthBuffer { uvec2 visibility_depth[]; };

// The work group's pixels' farthest depths so far, as bits (0: none, the nearest).
shared uint pixel_farthest[256];

// The farthest depth of the pixels of the texel `p` of level 0 (2×2 pixels), every thread of
// the work group taking part; pixels beyond the image count as the nearest depth, 0.
float group_farthest(uvec2 p, uvec2 image) {
    uint lid = gl_LocalInvocationIndex;
    for (uint i = lid; i < 256u; i += 64u) {
        pixel_farthest[i] = 0u;
    }
    barrier();
    // The work group's 8×8 texels (depth_pyramid_pass.glsl's 64 threads) cover 16×16 pixels
    // from `origin`.
    uvec2 origin = 16u * gl_WorkGroupID.xy;
    uint pairs = VISIBILITY_SAMPLES / 2u, row_pairs = 16u * pairs;
    for (uint g = lid; g < 16u * row_pairs; g += 64u) {
        uint row = g / row_pairs, within = g % row_pairs, px = within / pairs;
        uvec2 q = origin + uvec2(px, row);
        if (all(lessThan(q, image))) {
            uint first = 2u * ((q.y * image.x + q.x) * pairs + within % pairs);
            float farther = max(visibility_buffer_depth(visibility_depth[first]), visibility_buffer_depth(visibility_depth[first + 1u]));
            atomicMax(pixel_farthest[row * 16u + px], floatBitsToUint(farther));
        }
    }
    barrier();
    uvec2 t = 2u * gl_LocalInvocationID.xy;
    uint a = max(pixel_farthest[t.y * 16u + t.x], pixel_farthest[t.y * 16u + t.x + 1u]);
    uint b = max(pixel_farthest[(t.y + 1u) * 16u + t.x], pixel_farthest[(t.y + 1u) * 16u + t.x + 1u]);
    return uintBitsToFloat(max(a, b));
}

#define GROUP_FARTHEST 1
#include "visibility/depth_pyramid_pass.glsl"
