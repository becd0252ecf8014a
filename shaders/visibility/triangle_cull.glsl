// The triangle culling's work group (triangle_cull.comp, triangle_raster.comp): a meshlet
// drawn in this phase, its vertices transformed once into shared memory, a bit per triangle
// that goes to the hardware raster, and those triangles appended, in their meshlet's order,
// to the compacted index buffer of the phase's indexed draw.
// Needs common.glsl, meshlet_cull.glsl and meshlet_geometry.glsl; local_size_x = 64.

#ifndef MANYLIGHTS_TRIANGLE_CULL_GLSL
#define MANYLIGHTS_TRIANGLE_CULL_GLSL

// The rasteriser snaps vertices to its sub-pixel grid (8 bits on every device we run): a
// triangle is culled only with this much margin, in pixels, so snapping cannot bring it back.
const float SNAP = 1.0 / 64.0;

// Back faces seen nearly edge-on are kept: their orientation is as fragile as their area is
// small. Culled only where twice the area exceeds the perimeter times this (pixels).
const float EDGE_ON = 0.25;

shared vec4 clip[64];
shared uint kept[4]; // a bit per triangle
shared uint group_first;

// The points a pixel samples: its centre, or (the includer included visibility_samples.glsl
// first) the compute raster's samples.
#ifdef MANYLIGHTS_VISIBILITY_SAMPLES_GLSL
#define CULL_SAMPLES VISIBILITY_SAMPLES
#else
#define CULL_SAMPLES 1u
#endif

// Whether the triangle may cover a pixel centre (or sample); back faces count where `both_faces` (a
// double-sided object's).
bool triangle_visible(vec4 a, vec4 b, vec4 c, bool both_faces) {
    if (a.z < 0.0 && b.z < 0.0 && c.z < 0.0) {
        return false;
    }
    if (a.z > a.w && b.z > b.w && c.z > c.w) {
        return false;
    }
    if (a.w <= 0.0 || b.w <= 0.0 || c.w <= 0.0) {
        return true;
    }
    vec2 size = vec2(frame.viewport.xy);
    vec2 pa = (a.xy / a.w * 0.5 + 0.5) * size;
    vec2 pb = (b.xy / b.w * 0.5 + 0.5) * size;
    vec2 pc = (c.xy / c.w * 0.5 + 0.5) * size;
    if (both_faces && cross2(pb - pa, pc - pa) > 0.0) {
        // Seen from behind: tested as the front face it is drawn as.
        vec2 s = pb;
        pb = pc;
        pc = s;
    }
    // Framebuffer y points down: a counter-clockwise (front) face has a negative cross
    // product; the raster culls the others.
    vec3 edges = vec3(distance(pa, pb), distance(pb, pc), distance(pc, pa));
    float area = cross2(pb - pa, pc - pa);
    if (area > (edges.x + edges.y + edges.z) * EDGE_ON) {
        return false;
    }
    // The pixel centres (i + 0.5) inside the bounding box, within the image — with several
    // samples a pixel (the compute raster's anti-aliasing), the pixels the box reaches.
    float centre = 0.5;
    if (CULL_SAMPLES != 1u) {
        centre = 0.0;
    }
    vec2 first = max(ceil(min(pa, min(pb, pc)) - SNAP - centre) - (1.0 - 2.0 * centre), vec2(0.0));
    vec2 last = min(floor(max(pa, max(pb, pc)) + SNAP - centre), size - 1.0);
    if (any(greaterThan(first, last))) {
        return false;
    }
    // A small front face (at most 2×2 centres in its box): does it hold one of them? A
    // centre is outside where it lies beyond an edge by more than the margin.
    if (area >= 0.0 || any(greaterThan(last - first, vec2(1.0))) || centre == 0.0) {
        return true;
    }
    for (float y = first.y; y <= last.y; y += 1.0) {
        for (float x = first.x; x <= last.x; x += 1.0) {
            vec2 s = vec2(x, y) + 0.5;
            vec3 e = vec3(cross2(pb - pa, s - pa), cross2(pc - pb, s - pb), cross2(pa - pc, s - pc));
            if (all(lessThanEqual(e, edges * SNAP))) {
                return true;
            }
        }
    }
    return false;
}

// This work group's draw slot (x: meshlet instance; y: object; z: first vertex; w: meshlet).
uint group_slot() {
    return cull.mode.x * cull.mode.w + gl_WorkGroupID.x;
}

// The meshlet's vertices into `clip`, as visibility.vert transforms them; no triangle kept yet.
void transform_meshlet(Meshlet m, uvec4 d) {
    uint lid = gl_LocalInvocationID.x;
    if (lid < 4u) {
        kept[lid] = 0u;
    }
    if (lid < m.triangles.w) {
        uint b = VERTEX_FLOATS * meshlet_vertices[m.triangles.z + lid];
        vec3 world = (objects[d.y].model * vec4(vertex_data[b], vertex_data[b + 1u], vertex_data[b + 2u], 1.0)).xyz;
        clip[lid] = frame.proj * frame.view * vec4(world, 1.0);
    }
    barrier();
}

void keep_triangle(uint t) {
    atomicOr(kept[t >> 5u], 1u << (t & 31u));
}

// After every triangle's verdict: the kept ones appended to the phase's draw.
void append_kept(Meshlet m, uvec4 d) {
    uint phase = opaque_uniform(cull.mode.x);
    uint slot = group_slot();
    uint lid = gl_LocalInvocationID.x;
    barrier();
    uint total = bitCount(kept[0]) + bitCount(kept[1]) + bitCount(kept[2]) + bitCount(kept[3]);
    if (lid == 0u) {
        group_first = atomicAdd(counters.draws[phase].index_count, 3u * total) / 3u;
        if (phase == 0u) {
            atomicAdd(counters.triangles.z, total);
        } else {
            atomicAdd(counters.triangles.w, total);
        }
    }
    barrier();
    for (uint t = lid; t < m.triangles.y; t += gl_WorkGroupSize.x) {
        uint word = t >> 5u, bit = 1u << (t & 31u);
        if ((kept[word] & bit) == 0u) {
            continue;
        }
        uint before = bitCount(kept[word] & (bit - 1u));
        for (uint w = 0u; w < word; w++) {
            before += bitCount(kept[w]);
        }
        // The phase's k-th triangle: indices after the phase's first index, id at k of the
        // phase's id range (the raster's gl_PrimitiveID counts from 0 in each phase's draw).
        uint k = group_first + before;
        uvec3 v = meshlet_corners(m, t);
        uint at = counters.draws[phase].first_index + 3u * k;
        compacted_indices[at] = (slot << INDEX_VERTEX_BITS) | v.x;
        compacted_indices[at + 1u] = (slot << INDEX_VERTEX_BITS) | v.y;
        compacted_indices[at + 2u] = (slot << INDEX_VERTEX_BITS) | v.z;
        triangle_ids[phase * cull.triangles.x + k] = (d.x << VISIBILITY_TRIANGLE_BITS) | t;
    }
}

#endif
