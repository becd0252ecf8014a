#version 450
#extension GL_GOOGLE_include_directive : require
// The light grid's scan, between COUNT and FILL (light_grid_build.comp), over the lists
// (every cell, then the wide lights), in four steps, each wide but the third:
// A work group scans 1024 counts, four per invocation, as sums of four over its invocations.
//   STEP 0, a work group per block of 1024 lists: each count becomes its list's start
//           relative to the block; the block keeps its total and largest count;
//   STEP 1, a work group per 1024 blocks (a super-block): each block's total becomes its
//           start relative to the super-block, which keeps its total and largest count;
//   STEP 2, one work group: the super-blocks' totals become their starts (at most 1024
//           super-blocks: 2^30 lists), and the frame's totals go to the host-visible feedback;
//   STEP 3, wide again: each block's start becomes absolute.
// The lists' starts stay relative to their block (light_grid.glsl adds the block's).
#include "common/common.glsl"

layout(local_size_x = 256) in;
layout(constant_id = 0) const uint STEP = 0u;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 3) buffer LightGridCellBuffer { uint grid_cell_ends[]; };
// Per block: x its total, then its start; y its largest count.
layout(std430, set = 0, binding = 4) buffer LightGridBlockBuffer { uvec2 grid_blocks[]; };
// Per super-block: the same.
layout(std430, set = 0, binding = 8) buffer LightGridSuperBuffer { uvec2 grid_supers[]; };
layout(std430, set = 0, binding = 7) writeonly buffer LightGridFeedbackBuffer { LightGridFeedback feedback; };

const uint BLOCK = 1024u;
const uint THREADS = 256u;
const uint PER = BLOCK / THREADS;
shared uint scan[THREADS];
shared uint most[THREADS];

// Inclusive Hillis-Steele scan of scan[] and max-reduction of most[] over the work group.
void scan_workgroup(uint t) {
    for (uint step = 1u; step < THREADS; step <<= 1u) {
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

// The count (and largest count) of item i of a scan over lists (level 0), blocks (1) or
// super-blocks (2); zero beyond `size`.
uvec2 item(uint level, uint i, uint size) {
    if (i >= size) {
        return uvec2(0u);
    }
    return level == 0u ? uvec2(grid_cell_ends[i]) : level == 1u ? grid_blocks[i] : grid_supers[i];
}

void set_start(uint level, uint i, uint start) {
    if (level == 0u) {
        grid_cell_ends[i] = start;
    } else if (level == 1u) {
        grid_blocks[i].x = start;
    } else {
        grid_supers[i].x = start;
    }
}

// Scan the 1024 items of group g at `level` (each count becomes its start relative to the
// group); the group's total and largest count stay in scan[THREADS - 1], most[THREADS - 1].
void scan_group(uint level, uint g, uint t, uint size) {
    uint first = g * BLOCK + t * PER;
    uint counts[PER];
    uint sum = 0u;
    uint m = 0u;
    for (uint k = 0u; k < PER; ++k) {
        uvec2 c = item(level, first + k, size);
        counts[k] = c.x;
        sum += c.x;
        m = max(m, c.y);
    }
    scan[t] = sum;
    most[t] = m;
    barrier();
    scan_workgroup(t);
    uint start = scan[t] - sum;
    for (uint k = 0u; k < PER; ++k) {
        if (first + k < size) {
            set_start(level, first + k, start);
        }
        start += counts[k];
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
        if (g < blocks) {
            scan_group(0u, g, t, n);
            if (t == THREADS - 1u) {
                grid_blocks[g] = uvec2(scan[t], most[t]);
            }
        }
    } else if (STEP == 1u) {
        if (g < supers) {
            scan_group(1u, g, t, blocks);
            if (t == THREADS - 1u) {
                grid_supers[g] = uvec2(scan[t], most[t]);
            }
        }
    } else if (STEP == 2u) {
        scan_group(2u, 0u, t, supers);
        // The wide lights' list is the last: one invocation reports, once every start is written.
        memoryBarrierBuffer();
        barrier();
        if (t == 0u) {
            uint last = n - 1u;
            uint block = last / BLOCK;
            uint total = scan[THREADS - 1u];
            uint wide_start = grid_supers[block / BLOCK].x + grid_blocks[block].x + grid_cell_ends[last];
            feedback = LightGridFeedback(total, total - wide_start, most[THREADS - 1u], 0u);
        }
    } else {
        for (uint k = 0u; k < PER; ++k) {
            uint b = g * BLOCK + t * PER + k;
            if (b < blocks) {
                grid_blocks[b].x += grid_supers[b / BLOCK].x;
            }
        }
    }
}
