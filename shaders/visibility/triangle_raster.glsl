// The compute raster (docs/DESIGN.md#compute-raster), in place of culling step 3: a work group
// per meshlet drawn in this phase, its vertices transformed once into shared memory, a thread
// per triangle. A small triangle — bounding box within `cull.triangles.y` pixels a side, wholly
// beyond the near plane — is rasterised here, by Vulkan's rules as the hardware applies them:
// vertices snapped to 1/256 pixel, integer edge functions at pixel centres, the top-left rule
// on edges, depth interpolated from the vertices' z/w, LESS against what is there. The
// nearest (depth << 32 | visibility id) per pixel is kept by a 64-bit atomic min. Every other
// triangle (large, or crossing the near plane, which the hardware clips) is either clipped
// here and listed by the 64×64-pixel bins of its box for triangle_raster_large.comp (a work
// group each), or — the hybrid raster — goes to the phase's indexed draw, whose fragments do
// the same atomic min into the same buffer.
// A masked meshlet's small triangles are drawn by the whole work group together
// (draw_masked_meshlet). That path holds its triangles in shared memory, and a work group gets
// the shared memory of every shared variable its shader declares, whether or not
// specialization leaves code that touches it (measured on the H100: 0.118 against 0.111 ms for
// the bench scene's raster). So this file is compiled twice: triangle_raster.comp without it,
// for scenes without masked objects, and triangle_raster_masked.comp (MASKED_SURFACES) with it.
#include "common/common.glsl"

layout(local_size_x = 64) in;

#include "visibility/meshlet_cull.glsl"
#include "visibility/meshlet_geometry.glsl"
#include "visibility/visibility_samples.glsl"
#include "visibility/triangle_cull.glsl"

// Per pixel, row by row: floatBitsToUint(depth) << 32 | visibility id, the nearest kept; all
// ones where nothing was drawn (the depth pyramid and the lighting read it).
layout(std430, set = 0, binding = 14) buffer VisibilityDepthBuffer { uint64_t visibility_depth[]; };
// The large triangles and their bins (visibility_polygon.glsl), cull.triangles.z of each.
layout(std430, set = 0, binding = 15) writeonly buffer LargeBinBuffer { uvec2 large_bins[]; };
layout(std430, set = 0, binding = 16) buffer LargeTriangleBuffer { LargeTriangle large_triangles[]; };

#define ALPHA_MASK_BINDING 17
#include "common/alpha_mask.glsl"
#include "common/blended_cores.glsl"
// The transparent layers' candidates (cores' soft samples: the masked raster lists them).
#define LAYER_CANDIDATE_BINDING 18
#include "visibility/layer_candidates.glsl"
#include "visibility/visibility_polygon.glsl"

const uint ROUTE_NONE = 0u;    // no pixel to draw
const uint ROUTE_COMPUTE = 1u; // drawn here
const uint ROUTE_LARGE = 2u;   // listed by bins, or appended to the hybrid's indexed draw

shared uint group_triangles;
shared uint group_pixels;

// The viewport transform, in pixels.
vec2 framebuffer_xy(vec4 c) {
    return viewport_xy(c, vec2(frame.viewport.xy));
}

// In front of the near plane (or behind the eye) somewhere: the hardware clips it.
bool crosses_near_plane(vec4 a, vec4 b, vec4 c) {
    return a.z < 0.0 || b.z < 0.0 || c.z < 0.0 || a.w <= 0.0 || b.w <= 0.0 || c.w <= 0.0;
}

// Where a triangle wholly beyond the near plane is drawn, from its corners in pixels.
uint route(vec2 pa, vec2 pb, vec2 pc) {
    vec2 lo = min(pa, min(pb, pc)), hi = max(pa, max(pb, pc));
    if (any(greaterThan(hi - lo, vec2(float(cull.triangles.y))))) {
        return ROUTE_LARGE;
    }
    // Off screen, with a pixel of margin for the snapping.
    if (any(lessThan(hi, vec2(-1.0))) || any(greaterThan(lo, vec2(frame.viewport.xy) + 1.0))) {
        return ROUTE_NONE;
    }
    return ROUTE_COMPUTE;
}

// Where the triangle with clip-space corners a, b, c is drawn; where it lies wholly beyond the
// near plane, its corners in pixels `pa`, `pb`, `pc` too.
uint route_triangle(vec4 a, vec4 b, vec4 c, out vec2 pa, out vec2 pb, out vec2 pc) {
    if (crosses_near_plane(a, b, c)) {
        return ROUTE_LARGE;
    }
    pa = framebuffer_xy(a);
    pb = framebuffer_xy(b);
    pc = framebuffer_xy(c);
    return route(pa, pb, pc);
}

// Draws the triangle — its corners in pixels, their depths z/w — with visibility id `id`,
// both faces where `both_faces` (else the front alone, as the pipeline culls back faces),
// into every sample it covers; returns the samples covered. Every pixel it covers is kept: masked triangles are drawn by
// draw_masked_meshlet.
uint rasterize(vec2 pa, vec2 pb, vec2 pc, vec3 z, uint id, bool both_faces) {
    SmallTriangle t;
    if (!small_triangle(pa, pb, pc, ivec2(frame.viewport.xy), both_faces, t)) {
        return 0u;
    }
    if (t.swapped) {
        // Front faces come swapped: corners b and c.
        z = z.xzy;
    }
    // The edge functions at the first pixel's centre, stepped from pixel to pixel and out to
    // each sample (exact: integers), not evaluated afresh at every sample.
    ivec3 unit_x = -ivec3(t.c.y - t.b.y, t.a.y - t.c.y, t.b.y - t.a.y);
    ivec3 unit_y = ivec3(t.c.x - t.b.x, t.a.x - t.c.x, t.b.x - t.a.x);
    ivec3 row;
    small_covers(t, t.first, row);
    // A pixel where an edge function stays below its bias even with the most any sample adds
    // to the centre's value has no sample covered: its samples are not tested.
    ivec3 reach = ivec3(-0x7fffffff);
    [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
        ivec2 o = sample_offset(k) - 128;
        reach = max(reach, o.x * unit_x + o.y * unit_y);
    }
    ivec3 least = t.bias - reach;
    uint covered = 0u;
    for (int y = t.first.y; y <= t.last.y; y++, row += 256 * unit_y) {
        ivec3 centre = row;
        for (int x = t.first.x; x <= t.last.x; x++, centre += 256 * unit_x) {
            if (any(lessThan(centre, least))) {
                continue;
            }
            [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
                ivec2 o = sample_offset(k) - 128;
                ivec3 w = centre + o.x * unit_x + o.y * unit_y;
                if (any(lessThan(w - t.bias, ivec3(0)))) {
                    continue;
                }
                covered++;
                keep_nearest_id(ivec2(x, y), k, dot(vec3(w), z) / float(t.area), id);
            }
        }
    }
    return covered;
}

// A large triangle (or one crossing the near plane), clipped, into the list of large
// triangles and listed by the bins of its polygon's box; where the lists cannot hold it,
// drawn by this thread. Returns the samples it covered here.
uint list_large(vec4 a, vec4 b, vec4 c, uint id, uint flags, uint object, SurfaceTest s) {
    Polygon p = visibility_polygon(a, b, c);
    if (p.count == 0) {
        return 0u;
    }
    i64vec2 lo = p.s[0], hi = p.s[0];
    for (int i = 1; i < p.count; i++) {
        lo = min(lo, p.s[i]);
        hi = max(hi, p.s[i]);
    }
    ivec2 first, last;
    centres_in_box(ivec2(lo), ivec2(hi), ivec2(frame.viewport.xy), first, last);
    if (any(greaterThan(first, last))) {
        return 0u;
    }
    uvec2 bin0 = uvec2(first / BIN), span = uvec2(last / BIN) - bin0 + 1u;
    uint bins = span.x * span.y;
    uint phase = opaque_uniform(cull.mode.x), capacity = cull.triangles.z;
    uint triangle = atomicAdd(counters.binned[2u + phase], 1u);
    uint at = atomicAdd(counters.binned[phase], bins);
    bool fits = triangle < capacity && at <= capacity && bins <= capacity - at;
    if (fits) {
        store_large(triangle, p, id, flags, object, s);
    }
    for (uint i = 0u; i < bins && at + i < capacity; i++) {
        uvec2 bin = bin0 + uvec2(i % span.x, i / span.x);
        large_bins[at + i] = fits ? uvec2(triangle, bin.x | (bin.y << 16u)) : uvec2(NO_BIN);
    }
    if (fits) {
        atomicMax(counters.large[phase].x, min(at + bins, MAX_GROUPS));
        counters.large[phase].yz = uvec2(1u);
        return 0u;
    }
    atomicAdd(counters.rasterized.w, 1u);
    if (lists_candidates(s.alpha_texture.x)) {
        leave_cores_to_the_triangles();
    }
    return raster_polygon_alone(p, id, (flags & INSTANCE_DOUBLE_SIDED) != 0u, s);
}

#ifdef MASKED_SURFACES
// A masked meshlet's texture coordinates, its object's texture transform applied (the
// surface tests of its triangles).
shared vec2 corner_uv[64];

// A masked meshlet's corner uvs into `corner_uv` (the whole work group, its meshlet masked).
void load_corner_uvs(Meshlet m, uint object) {
    uint lid = gl_LocalInvocationID.x;
    if (lid < m.triangles.w) {
        uint b = VERTEX_FLOATS * meshlet_vertices[m.triangles.z + lid];
        corner_uv[lid] = transform_uv(objects[object].uv_transform, vec2(vertex_data[b + 6u], vertex_data[b + 7u]));
    }
    barrier();
}

// The small triangles of a masked meshlet are not drawn a thread each: the alpha test is most
// of a masked pixel's cost, and a thread walking its own triangle's box would test while the
// rest of its warp idles (at pixels outside their triangles, or done with smaller ones). So
// the work group sets up to 64 triangles at a time in shared memory and numbers the pixels
// of their boxes one after another; each thread then takes every 64th number, whichever
// triangle it falls in, so every thread has the same number of pixels to test. The points
// whose alpha the block bounds leave open are filtered after the others, together.
shared uvec4 mask_box_end[16];  // where the numbers of triangle i's box pixels end: [i / 4][i % 4]
shared ivec4 mask_edges[64];    // corners a, b, c snapped, relative to the first pixel's centre (16-bit x | y << 16 each); box width | fill biases (a bit each) << 16
shared ivec2 mask_box[64];      // first pixel (x | y << 16), twice the area
shared vec4 mask_z_inv_w[64];   // the corners' z/w, and 1/w of a
shared vec4 mask_uv_w[64];      // 1/w of b and c, u/w of a and b
shared vec4 mask_uv_w_rest[64]; // u/w of c, v/w of a, b, c

// Sets up the masked small triangle of thread `lid` — its corners in pixels, their depths
// z/w, its surface test `s` — as `rasterize` sets up a triangle, with its corners' uv/w and
// 1/w (perspective-correct from the edge functions, each corner's weight over its w, as the
// hardware interpolates); returns the pixels of its box (0: none to test).
uint set_up_masked(uint lid, vec2 pa, vec2 pb, vec2 pc, vec3 z, bool both_faces, SurfaceTest s) {
    SmallTriangle t;
    if (!small_triangle(pa, pb, pc, ivec2(frame.viewport.xy), both_faces, t) || any(greaterThan(t.first, t.last))) {
        return 0u;
    }
    vec3 inv_w = 1.0 / vec3(s.clip[0].w, s.clip[1].w, s.clip[2].w);
    vec3 u_w = vec3(s.uv[0].x, s.uv[1].x, s.uv[2].x) * inv_w;
    vec3 v_w = vec3(s.uv[0].y, s.uv[1].y, s.uv[2].y) * inv_w;
    if (t.swapped) {
        // Front faces come swapped: corners b and c.
        z = z.xzy;
        inv_w = inv_w.xzy;
        u_w = u_w.xzy;
        v_w = v_w.xzy;
    }
    ivec2 size = t.last - t.first + 1;
    // Corners relative to the first pixel's centre (edge functions do not change when the
    // origin moves): a box is at most 66 pixels a side (65, and a pixel more for samples off
    // the centre), so 16 signed bits hold each coordinate, and a pixel's coverage needs one
    // read of shared memory.
    ivec2 origin = t.first * 256 + 128 - t.lo;
    ivec2 a = t.a - origin, b = t.b - origin, c = t.c - origin;
    int bias = t.bias.x | (t.bias.y << 1) | (t.bias.z << 2);
    mask_edges[lid] = ivec4((a.x & 0xffff) | (a.y << 16), (b.x & 0xffff) | (b.y << 16), (c.x & 0xffff) | (c.y << 16), size.x | (bias << 16));
    mask_box[lid] = ivec2(t.first.x | (t.first.y << 16), t.area);
    mask_z_inv_w[lid] = vec4(z, inv_w.x);
    mask_uv_w[lid] = vec4(inv_w.yz, u_w.xy);
    mask_uv_w_rest[lid] = vec4(u_w.z, v_w);
    return uint(size.x * size.y);
}

// Points whose block bounds do not decide (near a cut-out's edge) are filtered after the
// others, together: (sample << 24 | triangle << 16 | pixel number in its box) of each, up to
// the capacity; past it, where they are found.
const uint MASK_FILTER_CAPACITY = 256u;
shared uint mask_filter[MASK_FILTER_CAPACITY];
shared uint mask_filtered;
const uint MASK_PIXEL_FILTER = 0xffffffffu;

// A corner as set_up_masked packs it: x in the low 16 bits, y in the high, both signed.
ivec2 unpack_corner(int packed) {
    return ivec2((packed << 16) >> 16, packed >> 16);
}

// Pixel `n` of triangle i's box (n from 0): `cell`, its place from the box's first pixel.
ivec2 masked_cell(uint i, uint n) {
    int width = mask_edges[i].w & 0xffff;
    // n / width without an integer division: n and width are small (a box is at most 66
    // pixels a side), so n + 0.5 lies at least 0.5 / width from a multiple of width, far more
    // than the float's rounding.
    int row = int((float(n) + 0.5) / float(width));
    return ivec2(int(n) - row * width, row);
}

// Whether triangle i covers sample k of the pixel at `cell` of its box; `w` the edge
// functions there.
bool masked_covers(uint i, ivec2 cell, uint k, out ivec3 w) {
    ivec4 edges = mask_edges[i];
    int bias = edges.w >> 16;
    ivec2 a = unpack_corner(edges.x), b = unpack_corner(edges.y), c = unpack_corner(edges.z);
    ivec2 p = cell * 256 + sample_offset(k) - 128;
    w = ivec3(edge_function(b, c, p), edge_function(c, a, p), edge_function(a, b, p));
    return all(greaterThanEqual(w - ivec3(bias & 1, (bias >> 1) & 1, bias >> 2), ivec3(0)));
}

// Whether triangle i covers any sample of pixel `n` of its box.
bool masked_covers_any(uint i, uint n) {
    ivec2 cell = masked_cell(i, n);
    [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
        ivec3 w;
        if (masked_covers(i, cell, k, w)) {
            return true;
        }
    }
    return false;
}

// Sample k of pixel `n` of triangle i's box drawn where the triangle covers it and its alpha
// keeps the sample's point; returns 1 where drawn, else 0, or MASK_PIXEL_FILTER where the
// texture must be filtered to tell and `filter_now` is false. `soft`: a core's sample's depth
// where it is for the layers (layer_candidates.glsl: drawn where its alpha is 1, soft where
// between), else -1.
uint draw_masked_sample(uint i, uint n, uint k, uint id, SurfaceTest s, bool filter_now, out float soft) {
    soft = -1.0;
    ivec2 cell = masked_cell(i, n);
    ivec3 w;
    if (!masked_covers(i, cell, k, w)) {
        return 0u;
    }
    ivec2 box = mask_box[i];
    vec4 z_inv_w = mask_z_inv_w[i], uv_w = mask_uv_w[i], uv_w_rest = mask_uv_w_rest[i];
    vec3 inv_w = vec3(z_inv_w.w, uv_w.xy), u_w = vec3(uv_w.zw, uv_w_rest.x), v_w = uv_w_rest.yzw;
    vec3 weights = vec3(w);
    float depth = dot(weights, z_inv_w.xyz) / float(box.y);
    vec2 uv = vec2(dot(weights, u_w), dot(weights, v_w)) / dot(weights, inv_w);
    ivec2 pixel = ivec2(box.x & 0xffff, box.x >> 16) + cell;
    if (lists_candidates(s.alpha_texture.x)) {
        uint verdict = core_sample_verdict(s.alpha, s.alpha_texture, uv);
        if (verdict == FILTER_SAMPLE && !filter_now) {
            return MASK_PIXEL_FILTER;
        }
        float alpha = core_sample_alpha(s.alpha, s.alpha_texture, uv, verdict);
        if (alpha < 1.0) {
            soft = soft_in_front(alpha, pixel, k, depth) ? depth : -1.0;
            return 0u;
        }
    } else {
        uint verdict = alpha_verdict(s.alpha, s.alpha_texture, uv);
        if (verdict == ALPHA_FILTER && !filter_now) {
            return MASK_PIXEL_FILTER;
        }
        if (verdict == ALPHA_DROPPED || (verdict == ALPHA_FILTER && !alpha_filtered_kept(s.alpha, s.alpha_texture, uv))) {
            return 0u;
        }
    }
    keep_nearest_id(pixel, k, depth, id);
    return 1u;
}

// Sample k of pixel `n` of triangle i's box (visibility id `id`) listed for the layers where
// soft (`soft`: its depth, else negative; every active lane calls it together).
void list_masked_soft_sample(float soft, uint i, uint n, uint k, uint id) {
    uvec4 c = uvec4(0u);
    if (soft >= 0.0) {
        c = layer_candidate(k, ivec2(mask_box[i].x & 0xffff, mask_box[i].x >> 16) + masked_cell(i, n), id, soft);
    }
    list_soft_sample(soft >= 0.0, c);
}

// Covered pixels (triangle << 16 | pixel number in its box) queued per subgroup, two
// subgroups' width each: about half of a box's pixels are outside its triangle, and a lane
// that tests the alpha of a covered pixel while its neighbours hold uncovered ones would run
// at half the subgroup's width. So the subgroup tests coverage (cheap) for the pixels dealt
// to it, queues the covered ones, and tests the alpha a full subgroup of them at a time.
shared uint mask_queue[2u * gl_WorkGroupSize.x];

// The first `count` pixels of the subgroup's queue (from `queue`; the meshlet's batch from
// triangle `first`) drawn, their samples dealt a lane each, a pixel's samples to neighbouring
// lanes: the atomics one instruction issues fall side by side in the buffer, where a lane
// drawing its pixel's samples one after another touched as many places as lanes (the cost
// of 64-bit atomics on the H200 follows the places). A sample the bounds leave open is
// listed to be filtered later; returns the samples drawn.
uint draw_queued(uint queue, uint count, uint first, uvec4 d, SurfaceTest s) {
    uint drawn = 0u;
    bool core = lists_candidates(s.alpha_texture.x);
    for (uint item = gl_SubgroupInvocationID; item < count * VISIBILITY_SAMPLES; item += gl_SubgroupSize) {
        uint e = mask_queue[queue + item / VISIBILITY_SAMPLES], k = item % VISIBILITY_SAMPLES;
        uint i = e >> 16u, n = e & 0xffffu, id = (d.x << VISIBILITY_TRIANGLE_BITS) | (first + i);
        float soft;
        uint got = draw_masked_sample(i, n, k, id, s, false, soft);
        if (got != MASK_PIXEL_FILTER) {
            drawn += got;
        } else {
            uint at = atomicAdd(mask_filtered, 1u);
            if (at < MASK_FILTER_CAPACITY) {
                mask_filter[at] = e | (k << 24u);
            } else {
                drawn += draw_masked_sample(i, n, k, id, s, true, soft);
            }
        }
        if (core) {
            list_masked_soft_sample(soft, i, n, k, id);
        }
    }
    return drawn;
}

// The meshlet's triangles, its object masked (`flags`: its instance's), by the whole work
// group; the counts of small triangles and of samples drawn are added to `triangles` and
// `pixels`.
void draw_masked_meshlet(Meshlet m, uvec4 d, bool culling, uint flags, SurfaceTest s, inout uint triangles, inout uint pixels) {
    uint lid = gl_LocalInvocationID.x;
    bool both_faces = (flags & INSTANCE_DOUBLE_SIDED) != 0u;
    if (lid == 0u) {
        mask_filtered = 0u;
    }
    // A transparent object's core: its large triangles' soft samples are listed where drawn.
    bool core = lists_candidates(s.alpha_texture.x);
    for (uint first = 0u; first < m.triangles.y; first += gl_WorkGroupSize.x) {
        uint box_pixels = 0u;
        uint t = first + lid;
        if (t < m.triangles.y) {
            uvec3 v = meshlet_corners(m, t);
            vec4 a = clip[v.x], b = clip[v.y], c = clip[v.z];
            if (!culling || triangle_visible(a, b, c, both_faces)) {
                uint id = (d.x << VISIBILITY_TRIANGLE_BITS) | t;
                s.clip[0] = a;
                s.clip[1] = b;
                s.clip[2] = c;
                s.uv[0] = corner_uv[v.x];
                s.uv[1] = corner_uv[v.y];
                s.uv[2] = corner_uv[v.z];
                vec2 pa, pb, pc;
                uint r = route_triangle(a, b, c, pa, pb, pc);
                if (core && r == ROUTE_LARGE && (opaque_uniform(cull.triangles.w) == 0u || crosses_near_plane(a, b, c))) {
                    // The hardware draws it, or it is clipped: not listed.
                    leave_cores_to_the_triangles();
                }
                if (r == ROUTE_LARGE && cull.triangles.w == 0u) {
                    keep_triangle(t);
                } else if (r == ROUTE_LARGE) {
                    pixels += list_large(a, b, c, id, flags, d.y, s);
                } else if (r == ROUTE_COMPUTE) {
                    box_pixels = set_up_masked(lid, pa, pb, pc, vec3(a.z / a.w, b.z / b.w, c.z / c.w), both_faces, s);
                    triangles++;
                }
            }
        }
        // The boxes' pixels numbered in the threads' order (the last batch's threads are done
        // with the numbers: the barrier at the end of the batch).
        mask_box_end[lid >> 2u][lid & 3u] = box_pixels;
        barrier();
        // A fixed count of reads (the same address in every thread at each step), which the
        // compiler issues back to back, not one after another's latency.
        uint end = 0u;
        for (uint j = 0u; j < 16u; j++) {
            uvec4 b = mask_box_end[j];
            uvec4 k = 4u * j + uvec4(0u, 1u, 2u, 3u);
            end += (k.x <= lid ? b.x : 0u) + (k.y <= lid ? b.y : 0u) + (k.z <= lid ? b.z : 0u) + (k.w <= lid ? b.w : 0u);
        }
        barrier();
        mask_box_end[lid >> 2u][lid & 3u] = end;
        barrier();
        uint total = mask_box_end[15].w;
        // Each thread's numbers grow, so the four triangles whose ends it reads only move on.
        // The loop is the same for every thread (a subgroup's ballots need all its lanes).
        uint j = 0u, queue = 2u * gl_SubgroupID * gl_SubgroupSize, lane = gl_SubgroupInvocationID;
        uint queued = 0u;
        for (uint n0 = 0u; n0 < total; n0 += gl_WorkGroupSize.x) {
            uint n = n0 + lid, entry = 0u;
            bool covered = false;
            if (n < total) {
                while (mask_box_end[j].w <= n) {
                    j++;
                }
                uvec4 ends = mask_box_end[j];
                uint before = j == 0u ? 0u : mask_box_end[j - 1u].w;
                bvec3 past = lessThanEqual(ends.xyz, uvec3(n));
                uint i = 4u * j + uint(past.x) + uint(past.y) + uint(past.z);
                uint start = past.z ? ends.z : past.y ? ends.y : past.x ? ends.x : before;
                covered = masked_covers_any(i, n - start);
                entry = (i << 16u) | (n - start);
            }
            uvec4 ballot = subgroupBallot(covered);
            if (covered) {
                mask_queue[queue + queued + subgroupBallotExclusiveBitCount(ballot)] = entry;
            }
            queued += subgroupBallotBitCount(ballot);
            if (queued >= gl_SubgroupSize) {
                subgroupMemoryBarrierShared();
                subgroupBarrier();
                pixels += draw_queued(queue, gl_SubgroupSize, first, d, s);
                uint rest = mask_queue[queue + gl_SubgroupSize + lane];
                subgroupBarrier();
                mask_queue[queue + lane] = rest;
                queued -= gl_SubgroupSize;
                subgroupMemoryBarrierShared();
                subgroupBarrier();
            }
        }
        subgroupMemoryBarrierShared();
        subgroupBarrier();
        pixels += draw_queued(queue, queued, first, d, s);
        barrier();
        uint filtered = min(mask_filtered, MASK_FILTER_CAPACITY);
        for (uint k = lid; k < filtered; k += gl_WorkGroupSize.x) {
            uint e = mask_filter[k], i = (e >> 16u) & 0xffu, id = (d.x << VISIBILITY_TRIANGLE_BITS) | (first + i);
            float soft;
            pixels += draw_masked_sample(i, e & 0xffffu, e >> 24u, id, s, true, soft);
            if (core) {
                list_masked_soft_sample(soft, i, e & 0xffffu, e >> 24u, id);
            }
        }
        barrier();
        if (lid == 0u) {
            mask_filtered = 0u;
        }
    }
}

#endif

void main() {
    uvec4 d = draw_slots[group_slot()];
    Meshlet m = meshlets[d.w];
    if (gl_LocalInvocationID.x == 0u) {
        group_triangles = 0u;
        group_pixels = 0u;
    }
    transform_meshlet(m, d);
    bool culling = opaque_uniform(cull.mode.y) != 0u;
    uint flags = SURFACE_TESTS ? instances[d.y].meshlets.w : 0u;
    bool both_faces = (flags & INSTANCE_DOUBLE_SIDED) != 0u;
    uint triangles = 0u, pixels = 0u;
#ifdef MASKED_SURFACES
    if ((flags & INSTANCE_MASKED) != 0u) {
        // Masked: the object's alpha test, the corners' uvs in shared memory (the flags are
        // the work group's: one meshlet, one object).
        load_corner_uvs(m, d.y);
        SurfaceTest s = no_surface_test();
        s.masked = true;
        s.alpha_texture = objects[d.y].alpha_texture;
        s.alpha = raster_alpha(objects[d.y].alpha, s.alpha_texture.x);
        draw_masked_meshlet(m, d, culling, flags, s, triangles, pixels);
    } else
#endif
    {
        for (uint t = gl_LocalInvocationID.x; t < m.triangles.y; t += gl_WorkGroupSize.x) {
            uvec3 v = meshlet_corners(m, t);
            vec4 a = clip[v.x], b = clip[v.y], c = clip[v.z];
            if (culling && !triangle_visible(a, b, c, both_faces)) {
                continue;
            }
            uint id = (d.x << VISIBILITY_TRIANGLE_BITS) | t;
            vec2 pa, pb, pc;
            uint r = route_triangle(a, b, c, pa, pb, pc);
            if (r == ROUTE_LARGE && cull.triangles.w == 0u) {
                keep_triangle(t);
            } else if (r == ROUTE_LARGE) {
                pixels += list_large(a, b, c, id, flags, d.y, no_surface_test());
            } else if (r == ROUTE_COMPUTE) {
                pixels += rasterize(pa, pb, pc, vec3(a.z / a.w, b.z / b.w, c.z / c.w), id, both_faces);
                triangles++;
            }
        }
    }
    atomicAdd(group_triangles, triangles);
    atomicAdd(group_pixels, pixels);
    append_kept(m, d);
    if (gl_LocalInvocationID.x == 0u) {
        atomicAdd(counters.rasterized[cull.mode.x], group_triangles);
        atomicAdd(counters.rasterized.z, group_pixels);
    }
}
