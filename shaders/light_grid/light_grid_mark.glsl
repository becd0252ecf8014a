// The light grid's marks (docs/DESIGN.md#the-light-grid): once the frame's opaque surfaces are
// known and before the build, a thread per pixel with a surface marks the cells its point's
// walk will visit (light_grid_walk.glsl). The build then lists only the lights of marked cells:
// a light whose cell no walk visits is tested by no pixel, so leaving it out changes nothing,
// and the lights far from every visible surface (most of them, at millions) cost the build a
// read and no more, and the lists hold only what the frame's pixels may test.
//
// The includer defines OPAQUE_DEPTH_BUFFER for the compute raster's 64-bit buffer.
#include "common/common.glsl"
#extension GL_EXT_control_flow_attributes : require

layout(local_size_x = 16, local_size_y = 16) in;

FRAME_BLOCK(0);
// Per 32 cells: x their marks (bit c % 32 for cell c); y is the build's. Coherent: a read sees
// the other work groups' marks so far (not a stale cached copy), and skips their atomics.
layout(std430, set = 0, binding = 31) coherent buffer LightGridOccupancyBuffer { uvec2 grid_occupancy[]; };

#include "common/opaque_depth.glsl"

#include "light_grid/light_grid_marking.glsl"

// The work group's box of cells (the union of its points' walks) and, where it has at most
// BOX_CELLS cells, their marks: the group's 256 points mostly walk the same cells, so they
// mark them here first and the group writes each word of the grid's marks once.
const uint BOX_CELLS = 4096u;
const uint GROUP_THREADS = 256u;
shared uint box_lo[3];
shared uint box_hi[3];
shared uint box_marks[BOX_CELLS / 32u];

// Mark cells u0..u1 of the box (one row along x). The group's points mostly mark the same
// cells: an atomic only where a bit is missing (bits are only set before the barrier that
// ends the marking, so an outdated read costs at most a needless atomic).
void mark_box_run(uint u0, uint u1) {
    for (uint word = u0 >> 5u; word <= u1 >> 5u; ++word) {
        uint bits = bits_between(max(u0, word << 5u) - (word << 5u), min(u1, (word << 5u) + 31u) - (word << 5u));
        if ((box_marks[word] & bits) != bits) {
            atomicOr(box_marks[word], bits);
        }
    }
}

// Whether walk w's cells lie within the box of cells [lo, hi].
bool cells_within(GridWalk w, uvec3 lo, uvec3 hi) {
    return all(greaterThanEqual(w.lo, lo)) && all(lessThanEqual(w.hi, hi));
}

#ifdef OPAQUE_DEPTH_BUFFER
// Anti-aliased: each surface of a pixel marks the walk from the point where the lighting
// shades it — the mean of its samples' positions (visibility_samples.glsl shading_xy) at the
// mean of their depths, found from the same samples the same way (visibility_lighting.glsl
// samples_of). Edge pixels have several surfaces: each is a walk of its own through the work
// group's box (one box around them all would mark the cells between a near surface and a far
// one).
#define MARK_SAMPLES VISIBILITY_SAMPLES

// The walk of the point where the lighting shades a surface of pixel p covering the samples
// `members` (`depths`: the sum of their depths). Depth is affine in the image over a
// triangle, so that is the surface's point at the mean position, up to rounding.
GridWalk surface_walk(ivec2 p, uint members, float depths) {
    return mark_walk_of(world_from_depth(shading_xy(p, members), depths / float(bitCount(members))));
}

// The surfaces of pixel p as the lighting groups its samples, each named by its first sample
// (a bit each: no array, which a loop would index in memory), and the walk of the first (most
// pixels hold one surface): the samples read once, held in registers for both.
uint pixel_leaders(ivec2 p, out GridWalk first) {
    uvec2 v[VISIBILITY_SAMPLES];
    [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
        v[k] = opaque_sample(p, k);
    }
    uint grouped = 0u, leaders = 0u;
    [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
        if ((grouped & (1u << k)) != 0u || visibility_buffer_depth(v[k]) >= 1.0) {
            continue;
        }
        leaders |= 1u << k;
        [[unroll]] for (uint j = k; j < VISIBILITY_SAMPLES; j++) {
            if (visibility_buffer_depth(v[j]) < 1.0 && visibility_buffer_id(v[j]) == visibility_buffer_id(v[k])) {
                grouped |= 1u << j;
            }
        }
    }
    if (leaders != 0u) {
        uint id = visibility_buffer_id(v[findLSB(leaders)]);
        uint members = 0u;
        float depths = 0.0;
        [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
            if (visibility_buffer_depth(v[k]) < 1.0 && visibility_buffer_id(v[k]) == id) {
                members |= 1u << k;
                depths += visibility_buffer_depth(v[k]);
            }
        }
        first = surface_walk(p, members, depths);
    }
    return leaders;
}

// The walk of pixel p's surface whose first sample is `leader`.
GridWalk leader_walk(ivec2 p, uint leader) {
    uint id = visibility_buffer_id(opaque_sample(p, leader));
    uint members = 0u;
    float depths = 0.0;
    [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
        uvec2 v = opaque_sample(p, k);
        if (visibility_buffer_depth(v) < 1.0 && visibility_buffer_id(v) == id) {
            members |= 1u << k;
            depths += visibility_buffer_depth(v);
        }
    }
    return surface_walk(p, members, depths);
}
#else
#define MARK_SAMPLES 1u
#endif

void main() {
    uint t = gl_LocalInvocationIndex;
    if (t < 3u) {
        box_lo[t] = 0xffffffffu;
        box_hi[t] = 0u;
    }
    for (uint i = t; i < BOX_CELLS / 32u; i += GROUP_THREADS) {
        box_marks[i] = 0u;
    }
    barrier();
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    bool inside = p.x < int(frame.viewport.x) && p.y < int(frame.viewport.y);
    // The pixel's walks: the centre point's (`centre`), or with anti-aliasing one per surface
    // (`leaders`, a bit each; `centre` the first's).
    GridWalk centre;
    uint leaders = 0u;
    if (MARK_SAMPLES == 1u) {
        float z = inside ? opaque_depth_at(p) : 1.0;
        leaders = z < 1.0 ? 1u : 0u;
        if (z < 1.0) {
            centre = mark_walk_of(world_from_depth(vec2(p) + 0.5, z));
        }
    }
#ifdef OPAQUE_DEPTH_BUFFER
    else if (inside) {
        leaders = pixel_leaders(p, centre);
    }
    uint all_leaders = leaders;
#define WALK(l) (MARK_SAMPLES == 1u || l == all_leaders ? centre : leader_walk(p, uint(findLSB(l))))
#else
#define WALK(l) centre
#endif
    // The box is the first surfaces' walks: a pixel's further surfaces (edge pixels') mostly
    // walk the same cells; each is walked once, below, into the box where it lies inside and
    // into the grid's marks where not.
    if (leaders != 0u) {
        for (uint a = 0u; a < 3u; ++a) {
            atomicMin(box_lo[a], centre.lo[a]);
            atomicMax(box_hi[a], centre.hi[a]);
        }
    }
    barrier();
    uvec3 lo = uvec3(box_lo[0], box_lo[1], box_lo[2]);
    uvec3 hi = uvec3(box_hi[0], box_hi[1], box_hi[2]);
    uvec3 n = lo.x > hi.x ? uvec3(0u) : hi - lo + 1u;
    bool in_box = n.x * n.y * n.z <= BOX_CELLS;
    // Not unrolled: each walk's code is large, and lavapipe builds a frame of every value live
    // across the barrier below (LLVM coroutines): 16 copies took it minutes.
    for (uint l = leaders; l != 0u; l &= l - 1u) {
        GridWalk w = WALK(l);
        // A walk's marks are its box of cells: a further surface's within the first's (the
        // pixel's surfaces lie within a pixel of each other) adds none.
        if (l != leaders && cells_within(w, centre.lo, centre.hi)) {
            continue;
        }
        if (!in_box || !cells_within(w, lo, hi)) {
            mark_rows(w);
            continue;
        }
        for (uint cz = w.lo.z; cz <= w.hi.z; ++cz) {
            for (uint cy = w.lo.y; cy <= w.hi.y; ++cy) {
                uint row = ((cz - lo.z) * n.y + (cy - lo.y)) * n.x - lo.x;
                mark_box_run(row + w.lo.x, row + w.hi.x);
            }
        }
    }
    barrier();
    if (in_box) {
        // A box row per invocation: its marked cells, a word of the grid's marks at a time.
        for (uint r = t; r < n.y * n.z; r += GROUP_THREADS) {
            uint cell0 = ((lo.z + r / n.y) * frame.light_grid_dims.y + lo.y + r % n.y) * frame.light_grid_dims.x + lo.x;
            uint bits = 0u;
            uint word = cell0 >> 5u;
            for (uint x = 0u; x < n.x; ++x) {
                uint c = cell0 + x;
                if ((c >> 5u) != word) {
                    if (bits != 0u) {
                        mark_word(word, bits);
                    }
                    word = c >> 5u;
                    bits = 0u;
                }
                uint u = r * n.x + x;
                if ((box_marks[u >> 5u] & (1u << (u & 31u))) != 0u) {
                    bits |= 1u << (c & 31u);
                }
            }
            if (bits != 0u) {
                mark_word(word, bits);
            }
        }
    }
}
