#version 450
#extension GL_GOOGLE_include_directive : require
// The depth pyramid's levels above the first (depth_pyramid_pass.glsl makes level 0 from the
// raster), up to six a dispatch: a work group reduces a 64×64 block of the level below it to
// 32×32 texels of the first level it writes, then on in shared memory down to one texel,
// writing each level as it is made. Each texel is the farthest of its four children (clamped
// to the level below, as depth_pyramid_pass.glsl reads them), so the buffer holds the same
// values as a dispatch per level would write, with a barrier between dispatches only every
// six levels: at 1080p three dispatches make the eleven levels.
#include "common/common.glsl"
#include "visibility/depth_pyramid.glsl"

layout(local_size_x = 16, local_size_y = 16) in;

layout(std430, set = 0, binding = 1) buffer DepthPyramidBuffer { float depth_pyramid[]; };
// x: the first level written (at least 1); yz: the image's size; w: the level after the last
// one written.
layout(push_constant) uniform PyramidLevelsPushBlock { uvec4 level; };

// The work group's texels of the level being made (TILE a side on the first level, half as
// many on each one after).
const uint TILE = 32u;
shared float tile[TILE][TILE];

void main() {
    uvec2 image = level.yz;
    int first = int(opaque_uniform(level.x)), end = int(opaque_uniform(level.w));
    uvec2 local = gl_LocalInvocationID.xy;
    // The first level: 2×2 texels a thread, each from its children in the buffer.
    uvec2 origin = gl_WorkGroupID.xy * TILE;
    uvec2 size = pyramid_level_size(image, first), below = pyramid_level_size(image, first - 1);
    uint at = pyramid_level_offset(image, first), at_below = pyramid_level_offset(image, first - 1);
    for (uint i = 0u; i < 4u; i++) {
        uvec2 t = 2u * local + uvec2(i & 1u, i >> 1u), p = origin + t;
        float farthest = 0.0;
        if (all(lessThan(p, size))) {
            for (uint j = 0u; j < 4u; j++) {
                uvec2 q = min(2u * p + uvec2(j & 1u, j >> 1u), below - 1u);
                farthest = max(farthest, depth_pyramid[at_below + q.y * below.x + q.x]);
            }
            depth_pyramid[at + p.y * size.x + p.x] = farthest;
        }
        tile[t.y][t.x] = farthest;
    }
    // Each level after, from the tile of the one before: the tile's texels of a level lie
    // from `origin` (on it) on, and a texel inside its level has its children (clamped to
    // the level below) inside the tile below.
    uint side = TILE / 2u;
    for (int l = first + 1; l < end; l++, side /= 2u) {
        uvec2 origin_below = origin;
        origin /= 2u;
        below = size;
        size = pyramid_level_size(image, l);
        at = pyramid_level_offset(image, l);
        uvec2 p = origin + local;
        bool inside = all(lessThan(local, uvec2(side))) && all(lessThan(p, size));
        barrier();
        float farthest = 0.0;
        if (inside) {
            for (uint j = 0u; j < 4u; j++) {
                uvec2 q = min(2u * p + uvec2(j & 1u, j >> 1u), below - 1u) - origin_below;
                farthest = max(farthest, tile[q.y][q.x]);
            }
        }
        barrier();
        if (inside) {
            tile[local.y][local.x] = farthest;
            depth_pyramid[at + p.y * size.x + p.x] = farthest;
        }
    }
}
