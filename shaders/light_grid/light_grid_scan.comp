#version 450
#extension GL_GOOGLE_include_directive : require
// The light grid's scan, between COUNT and FILL (light_grid_build.comp), over the lists
// (every cell, then the wide lights), in two steps that scale to 2^27 lists:
//   STEP 0, a work group per block of GRID_BLOCK lists: each count becomes its list's start
//           relative to the block; the block's total and largest count are kept;
//   STEP 1, one work group: the block totals become the blocks' starts (1024 at a time,
//           carrying the sum), and the frame's totals go to the host-visible feedback.
#include "common/common.glsl"

layout(local_size_x = 1024) in;
layout(constant_id = 0) const uint STEP = 0u;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 3) buffer LightGridCellBuffer { uint grid_cell_ends[]; };
// Per block: x its total, then its start; y its largest count.
layout(std430, set = 0, binding = 4) buffer LightGridBlockBuffer { uvec2 grid_blocks[]; };
layout(std430, set = 0, binding = 7) writeonly buffer LightGridFeedbackBuffer { LightGridFeedback feedback; };

const uint BLOCK = 1024u;
shared uint scan[BLOCK];
shared uint most[BLOCK];

// Inclusive Hillis-Steele scan of scan[] and max-reduction of most[] over the work group.
void scan_workgroup(uint t) {
    for (uint step = 1u; step < BLOCK; step <<= 1u) {
        uint add = t >= step ? scan[t - step] : 0u;
        uint m = t >= step ? most[t - step] : 0u;
        barrier();
        scan[t] += add;
        most[t] = max(most[t], m);
        barrier();
    }
}

void main() {
    // Every cell and the wide lights' list.
    uint n = frame.light_grid_dims.w + 1u;
    uint t = gl_LocalInvocationID.x;
    if (STEP == 0u) {
        // Work groups come in rows (a device takes at most 65,535 along x).
        uint block = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
        if (block * BLOCK >= n) {
            return;
        }
        uint i = block * BLOCK + t;
        uint count = i < n ? grid_cell_ends[i] : 0u;
        scan[t] = count;
        most[t] = count;
        barrier();
        scan_workgroup(t);
        if (i < n) {
            grid_cell_ends[i] = scan[t] - count;
        }
        if (t == BLOCK - 1u) {
            grid_blocks[block] = uvec2(scan[t], most[t]);
        }
    } else {
        uint blocks = (n + BLOCK - 1u) / BLOCK;
        uint carry = 0u;
        uint largest = 0u;
        // The wide lights' list is the last: the invocation of its block keeps the block's start.
        uint last = n - 1u;
        uint wide_block_start = 0u;
        for (uint first = 0u; first < blocks; first += BLOCK) {
            uint b = first + t;
            uvec2 block = b < blocks ? grid_blocks[b] : uvec2(0u);
            scan[t] = block.x;
            most[t] = block.y;
            barrier();
            scan_workgroup(t);
            if (b < blocks) {
                grid_blocks[b].x = carry + scan[t] - block.x;
            }
            if (b == last / BLOCK) {
                wide_block_start = carry + scan[t] - block.x;
            }
            carry += scan[BLOCK - 1u];
            largest = max(largest, most[BLOCK - 1u]);
            barrier();
        }
        if (t == (last / BLOCK) % BLOCK) {
            // Its count: the total less its start.
            uint wide_start = wide_block_start + grid_cell_ends[last];
            feedback = LightGridFeedback(carry, carry - wide_start, largest, 0u);
        }
    }
}
