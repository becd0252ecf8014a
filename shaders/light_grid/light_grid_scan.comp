#version 450
#extension GL_GOOGLE_include_directive : require
// The light grid's scans (exclusive prefix sums) in three steps, of
//   SOURCE 1, the marks (after light_grid_mark.glsl, before COUNT): per 32 cells the marked
//             ones become the list of their first, so that every marked cell gets a list
//             (list 0 is the wide lights'), the lists' counts are zeroed for COUNT, and the
//             lists' scan gets its work groups (LightGridDispatch);
//   SOURCE 0, the lists' counts (between COUNT and FILL, light_grid_build.comp): each becomes
//             its list's start (FILL's cursor; after FILL its end, what the walk reads).
// Blocks of 1024 counts, four per invocation:
//   STEP 0, a work group per block: the block's total and largest count;
//   STEP 1, one work group: the blocks' totals become their starts, 4096 at a time; the
//           totals go where the source says;
//   STEP 2, a work group per block: each count becomes its start (the block's, plus those
//           before it in the block).
#include "common/common.glsl"

layout(local_size_x = 256) in;
layout(constant_id = 0) const uint STEP = 0u;
layout(constant_id = 1) const uint SOURCE = 0u;

FRAME_BLOCK(0);
layout(std430, set = 0, binding = 3) buffer LightGridListBuffer { uint grid_lists[]; };
layout(std430, set = 0, binding = 4) buffer LightGridOccupancyBuffer { uvec2 grid_occupancy[]; };
// Per block: x its total, then its start; y its largest count.
layout(std430, set = 0, binding = 8) buffer LightGridBlockBuffer { uvec2 grid_blocks[]; };
layout(std430, set = 0, binding = 7) buffer LightGridFeedbackBuffer { LightGridFeedback feedback; };
layout(std430, set = 0, binding = 13) buffer LightGridDispatchBuffer { LightGridDispatch grid_dispatch; };

const uint BLOCK = 1024u;
const uint THREADS = 256u;
const uint PER = BLOCK / THREADS;
// Blocks STEP 1 takes per round (16 an invocation).
const uint ROUND = 16u * THREADS;
// Work groups a dispatch puts along x before it adds rows (light_grid_build.rs GROUPS_PER_ROW).
const uint GROUPS_PER_ROW = 32768u;
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

// Word i's marks, its bits beyond the last cell left out.
uint word_marks(uint i) {
    uint beyond = (i + 1u) * 32u - min((i + 1u) * 32u, frame.light_grid_dims.w);
    return grid_occupancy[i].x & (0xffffffffu >> beyond);
}

// How many counts the source has: words of marks, or lists.
uint source_size() {
    return SOURCE == 1u ? (frame.light_grid_dims.w + 31u) / 32u : grid_dispatch.lists;
}

// Count i of the source (zero beyond its size).
uint source_count(uint i, uint size) {
    if (i >= size) {
        return 0u;
    }
    return SOURCE == 1u ? bitCount(word_marks(i)) : grid_lists[i];
}

// A dispatch of `groups` work groups as rows of GROUPS_PER_ROW.
uvec4 dispatch_rows(uint groups) {
    groups = max(groups, 1u);
    return groups <= GROUPS_PER_ROW ? uvec4(groups, 1u, 1u, 0u) : uvec4(GROUPS_PER_ROW, (groups + GROUPS_PER_ROW - 1u) / GROUPS_PER_ROW, 1u, 0u);
}

// STEP 1's totals: the marked cells give the lists (and the lists' scan its work groups); the
// lists give what the build reports.
void report(uint total, uint largest) {
    if (SOURCE == 1u) {
        uint lists = total + 1u;
        grid_dispatch.lists = lists;
        grid_dispatch.block_groups = dispatch_rows((lists + BLOCK - 1u) / BLOCK);
        feedback.cells_marked = total;
    } else {
        feedback.listed = total;
        feedback.max_count = largest;
    }
}

// STEP 2: count i starts at `start`. A word of marks gives its first marked cell its list
// (after the wide lights' list 0; the others follow it by rank); a list keeps its start for
// FILL.
void set_start(uint i, uint start, uint count) {
    if (SOURCE == 1u) {
        grid_occupancy[i].y = start + 1u;
    } else {
        grid_lists[i] = start;
        if (i == 0u) {
            feedback.wide = count;
        }
    }
}

void main() {
    uint n = source_size();
    uint blocks = (n + BLOCK - 1u) / BLOCK;
    uint t = gl_LocalInvocationID.x;
    uint g = group_index();
    if (STEP == 1u) {
        // One work group over every block, ROUND at a time, carrying the sum.
        uint carry = 0u;
        uint largest = 0u;
        for (uint first = 0u; first < blocks; first += ROUND) {
            uint sum = 0u;
            uint m = 0u;
            for (uint k = 0u; k < 16u; ++k) {
                uint b = first + t * 16u + k;
                if (b < blocks) {
                    sum += grid_blocks[b].x;
                    m = max(m, grid_blocks[b].y);
                }
            }
            scan[t] = sum;
            most[t] = m;
            barrier();
            scan_workgroup(t);
            uint start = carry + scan[t] - sum;
            for (uint k = 0u; k < 16u; ++k) {
                uint b = first + t * 16u + k;
                if (b < blocks) {
                    uint total = grid_blocks[b].x;
                    grid_blocks[b].x = start;
                    start += total;
                }
            }
            carry += scan[THREADS - 1u];
            largest = max(largest, most[THREADS - 1u]);
            barrier();
        }
        if (t == 0u) {
            report(carry, largest);
        }
        return;
    }
    if (g >= blocks) {
        return;
    }
    uint first = g * BLOCK + t * PER;
    uint counts[PER];
    uint sum = 0u;
    uint m = 0u;
    for (uint k = 0u; k < PER; ++k) {
        counts[k] = source_count(first + k, n);
        sum += counts[k];
        m = max(m, counts[k]);
    }
    scan[t] = sum;
    most[t] = m;
    barrier();
    scan_workgroup(t);
    if (STEP == 0u) {
        if (t == THREADS - 1u) {
            grid_blocks[g] = uvec2(scan[t], most[t]);
        }
        return;
    }
    uint start = grid_blocks[g].x + scan[t] - sum;
    if (SOURCE == 1u) {
        // The block's marked cells have the lists from its start on (after list 0): zero
        // their counts for COUNT, side by side.
        uint lists = scan[THREADS - 1u];
        for (uint j = t; j < lists; j += THREADS) {
            grid_lists[grid_blocks[g].x + 1u + j] = 0u;
        }
        if (g == 0u && t == 0u) {
            grid_lists[0] = 0u;
        }
    }
    for (uint k = 0u; k < PER; ++k) {
        if (first + k < n) {
            set_start(first + k, start, counts[k]);
        }
        start += counts[k];
    }
}
