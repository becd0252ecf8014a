#version 450
#extension GL_GOOGLE_include_directive : require
// The light grid's scans (exclusive prefix sums), in five steps, each wide but the third, of
//   SOURCE 1, the marks (after light_grid_mark.glsl, before COUNT): per 32 cells the marked
//             ones become the list of their first, so that every marked cell gets a list
//             (list 0 is the wide lights'); their lists' counts are zeroed for COUNT, and the
//             lists' scan gets its work groups (LightGridDispatch);
//   SOURCE 0, the lists' counts (between COUNT and FILL, light_grid_build.comp): each becomes
//             its list's start (and one past the last list holds the total).
// A work group scans 1024 counts, four per invocation, as sums of four over its invocations.
//   STEP 0, a work group per block of 1024 counts: each becomes its start relative to the
//           block; the block keeps its total and largest count;
//   STEP 1, a work group per 1024 blocks (a super-block): each block's total becomes its
//           start relative to the super-block, which keeps its total and largest count;
//   STEP 2, one work group: the super-blocks' totals become their starts (at most 1024
//           super-blocks: 2^30 counts), and the totals go where the source says;
//   STEP 3, a work group per super-block: each block's start becomes absolute;
//   STEP 4, a work group per block: each start becomes absolute;
//   STEP 5 (marks only, after the lists' scan), a work group per block of words: each marked
//           cell's range of the lists (light_grid.glsl grid_cell_ranges), and the wide lights'.
#include "common/common.glsl"

layout(local_size_x = 256) in;
layout(constant_id = 0) const uint STEP = 0u;
layout(constant_id = 1) const uint SOURCE = 0u;

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 3) buffer LightGridListBuffer { uint grid_list_ends[]; };
layout(std430, set = 0, binding = 4) buffer LightGridOccupancyBuffer { uvec2 grid_occupancy[]; };
// Per block: x its total, then its start; y its largest count.
layout(std430, set = 0, binding = 8) buffer LightGridBlockBuffer { uvec2 grid_blocks[]; };
// Per super-block: the same.
layout(std430, set = 0, binding = 12) buffer LightGridSuperBuffer { uvec2 grid_supers[]; };
layout(std430, set = 0, binding = 7) buffer LightGridFeedbackBuffer { LightGridFeedback feedback; };
layout(std430, set = 0, binding = 13) buffer LightGridDispatchBuffer { LightGridDispatch grid_dispatch; };
layout(std430, set = 0, binding = 15) writeonly buffer LightGridCellRangeBuffer { uvec2 grid_cell_ranges[]; };

const uint BLOCK = 1024u;
const uint THREADS = 256u;
const uint PER = BLOCK / THREADS;
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

// Counts the source scans: the marked cells per 32 (the last word's bits beyond the cells
// left out), or the lists.
uint source_size() {
    return SOURCE == 1u ? (frame.light_grid_dims.w + 31u) / 32u : grid_dispatch.lists;
}

// Word i's marks, its bits beyond the last cell left out.
uint word_marks(uint i) {
    uint beyond = (i + 1u) * 32u - min((i + 1u) * 32u, frame.light_grid_dims.w);
    return grid_occupancy[i].x & (0xffffffffu >> beyond);
}

uint source_count(uint i) {
    return SOURCE == 1u ? bitCount(word_marks(i)) : grid_list_ends[i];
}

// The count (and largest count) of item i of a scan over the source (level 0), blocks (1) or
// super-blocks (2); zero beyond `size`.
uvec2 item(uint level, uint i, uint size) {
    if (i >= size) {
        return uvec2(0u);
    }
    return level == 0u ? uvec2(source_count(i)) : level == 1u ? grid_blocks[i] : grid_supers[i];
}

void set_start(uint level, uint i, uint start) {
    if (level == 0u) {
        if (SOURCE == 1u) {
            grid_occupancy[i].y = start;
        } else {
            grid_list_ends[i] = start;
        }
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

// A dispatch of `groups` work groups as rows of GROUPS_PER_ROW.
uvec4 dispatch_rows(uint groups) {
    groups = max(groups, 1u);
    return groups <= GROUPS_PER_ROW ? uvec4(groups, 1u, 1u, 0u) : uvec4(GROUPS_PER_ROW, (groups + GROUPS_PER_ROW - 1u) / GROUPS_PER_ROW, 1u, 0u);
}

// STEP 2's totals: the marked cells give the lists (and the lists' scan its work groups); the
// lists give what the build reports.
void report(uint total, uint largest) {
    if (SOURCE == 1u) {
        uint lists = total + 1u;
        uint blocks = (lists + BLOCK - 1u) / BLOCK;
        grid_dispatch.lists = lists;
        grid_dispatch.block_groups = dispatch_rows(blocks);
        grid_dispatch.super_groups = dispatch_rows((blocks + BLOCK - 1u) / BLOCK);
        feedback.cells_marked = total;
    } else {
        // List 0 is the wide lights': list 1 starts where it ends (block 0 starts at 0).
        grid_list_ends[grid_dispatch.lists] = total;
        feedback.listed = total;
        feedback.wide = grid_dispatch.lists > 1u ? grid_list_ends[1] : total;
        feedback.max_count = largest;
    }
}

// STEP 4 for item i of block g: its start becomes absolute; a word of marks then also zeroes
// its lists' counts for COUNT.
void finish_item(uint i, uint g) {
    if (SOURCE == 1u) {
        uint list = grid_occupancy[i].y + grid_blocks[g].x + 1u;
        grid_occupancy[i].y = list;
        uint marked = source_count(i);
        for (uint k = 0u; k < marked; ++k) {
            grid_list_ends[list + k] = 0u;
        }
        if (i == 0u) {
            grid_list_ends[0] = 0u;
        }
    } else {
        grid_list_ends[i] += grid_blocks[g].x;
    }
}

// STEP 5 for word i of marks: each marked cell's range of the lists (whose starts the
// lists' scan left, one past the last list holding the total); word 0 also the wide lights'.
void write_ranges(uint i) {
    uint bits = word_marks(i);
    uint list = grid_occupancy[i].y;
    while (bits != 0u) {
        uint c = i * 32u + uint(findLSB(bits));
        grid_cell_ranges[c] = uvec2(grid_list_ends[list], grid_list_ends[list + 1u]);
        list++;
        bits &= bits - 1u;
    }
    if (i == 0u) {
        grid_cell_ranges[frame.light_grid_dims.w] = uvec2(0u, grid_list_ends[1]);
    }
}

void main() {
    uint n = source_size();
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
        // One invocation reports, once every start is written.
        memoryBarrierBuffer();
        barrier();
        if (t == 0u) {
            report(scan[THREADS - 1u], most[THREADS - 1u]);
        }
    } else if (STEP == 3u) {
        for (uint k = 0u; k < PER; ++k) {
            uint b = g * BLOCK + t * PER + k;
            if (b < blocks) {
                grid_blocks[b].x += grid_supers[b / BLOCK].x;
            }
        }
    } else if (STEP == 4u) {
        for (uint k = 0u; k < PER; ++k) {
            uint i = g * BLOCK + t * PER + k;
            if (i < n) {
                finish_item(i, g);
            }
        }
    } else {
        for (uint k = 0u; k < PER; ++k) {
            uint i = g * BLOCK + t * PER + k;
            if (i < n) {
                write_ranges(i);
            }
        }
    }
}
