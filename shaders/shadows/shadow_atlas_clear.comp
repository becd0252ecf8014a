#version 450
#extension GL_GOOGLE_include_directive : require
// The shadow atlas's step 0 (omni_raster.glsl with ATLAS): every face drawn this frame is
// cleared to 1.0 (beyond the light's reach) before the culling lists what reaches it. A work
// group per (redrawn light, face, sixteenth of the face): a face's texels are one run of the
// Z-ordered atlas, so each group writes a contiguous range. Faces kept from last frame are
// left alone.
#include "common/common.glsl"

layout(local_size_x = 256) in;

#include "shadows/omni_raster.glsl"

const uint SLICES = 16u;

void main() {
    uint light = redrawn_lights[gl_WorkGroupID.x], face = gl_WorkGroupID.y;
    if ((cube_tiles[light].redraw & (1u << face)) == 0u) {
        return;
    }
    uint side = cube_tiles[light].size;
    // Faces are at least 32² texels: a sixteenth is a whole number of them.
    uint part = side * side / SLICES;
    uint first = cube_tiles[light].base[face] + gl_WorkGroupID.z * part;
    for (uint i = gl_LocalInvocationID.x; i < part; i += gl_WorkGroupSize.x) {
        cube_depth[first + i] = floatBitsToUint(1.0);
    }
}
