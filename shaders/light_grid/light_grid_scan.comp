#version 450
#extension GL_GOOGLE_include_directive : require
// The light grid's scan, between COUNT and FILL (light_grid_build.comp), over the lists
// (every cell, then the wide lights), in four steps, each wide but the third:
//   STEP 0, a work group per block of 1024 lists: each count becomes its list's start
//           relative to the block; the block keeps its total and largest count;
//   STEP 1, a work group per 1024 blocks (a super-block): each block's total becomes its
//           start relative to the super-block, which keeps its total and largest count;
//   STEP 2, one work group: the super-blocks' totals become their starts (at most 1024
//           super-blocks: 2^30 lists), and the frame's totals go to the host-visible feedback;
//   STEP 3, an invocation per block: its start becomes absolute.
// The lists' starts stay relative to their block (light_grid.glsl adds the block's).
#include "common/common.glsl"

layout(local_size_x = 1024) in;
layout(constant_id = 0) const uint STEP = 0u;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 3) buffer LightGridCellBuffer { uint grid_cell_ends[]; };
// Per block: x its total, then its start; y its largest count.
layout(std430, set = 0, binding = 4) buffer LightGridBlockBuffer { uvec2 grid_blocks[]; };
// Per super-block: the same.
layout(std430, set = 0, binding = 8) buffer LightGridSuperBuffer { uvec2 grid_supers[]; };
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

// The work group's number (they come in rows: a device takes at most 65,535 along x).
uint group_index() {
    return gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
}

// Scan a group of counts: the lists of block g (STEP 0), or the blocks of super-block g
// (STEP 1).
void scan_counts(uint g, uint t, uint n, uint blocks, bool of_blocks) {
    uint size = of_blocks ? blocks : n;
    if (g * BLOCK >= size) {
        return;
    }
    uint i = g * BLOCK + t;
    uvec2 count = uvec2(0u);
    if (i < size) {
        count = of_blocks ? grid_blocks[i] : uvec2(grid_cell_ends[i]);
    }
    scan[t] = count.x;
    most[t] = count.y;
    barrier();
    scan_workgroup(t);
    if (i < size) {
        if (of_blocks) {
            grid_blocks[i].x = scan[t] - count.x;
        } else {
            grid_cell_ends[i] = scan[t] - count.x;
        }
    }
    if (t == BLOCK - 1u) {
        if (of_blocks) {
            grid_supers[g] = uvec2(scan[t], most[t]);
        } else {
            grid_blocks[g] = uvec2(scan[t], most[t]);
        }
    }
}

void main() {
    // Every cell and the wide lights' list.
    uint n = frame.light_grid_dims.w + 1u;
    uint blocks = (n + BLOCK - 1u) / BLOCK;
    uint supers = (blocks + BLOCK - 1u) / BLOCK;
    uint t = gl_LocalInvocationID.x;
    uint g = group_index();
    if (STEP == 0u) {
        scan_counts(g, t, n, blocks, false);
    } else if (STEP == 1u) {
        scan_counts(g, t, n, blocks, true);
    } else if (STEP == 2u) {
        uvec2 s = t < supers ? grid_supers[t] : uvec2(0u);
        scan[t] = s.x;
        most[t] = s.y;
        barrier();
        scan_workgroup(t);
        if (t < supers) {
            grid_supers[t].x = scan[t] - s.x;
        }
        // The wide lights' list is the last: its super-block's invocation reports.
        uint last = n - 1u;
        uint block = last / BLOCK;
        if (t == block / BLOCK) {
            uint total = scan[BLOCK - 1u];
            uint wide_start = scan[t] - s.x + grid_blocks[block].x + grid_cell_ends[last];
            feedback = LightGridFeedback(total, total - wide_start, most[BLOCK - 1u], 0u);
        }
    } else {
        uint b = g * BLOCK + t;
        if (b < blocks) {
            grid_blocks[b].x += grid_supers[b / BLOCK].x;
        }
    }
}
