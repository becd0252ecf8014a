#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
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
#include "common/common.glsl"

layout(local_size_x = 64) in;

#include "visibility/meshlet_cull.glsl"
#include "visibility/meshlet_geometry.glsl"
#include "visibility/triangle_cull.glsl"

// Per pixel, row by row: floatBitsToUint(depth) << 32 | visibility id, the nearest kept; all
// ones where nothing was drawn (the depth pyramid and the lighting read it).
layout(std430, set = 0, binding = 14) buffer VisibilityDepthBuffer { uint64_t visibility_depth[]; };
// The large triangles and their bins (visibility_polygon.glsl), cull.triangles.z of each.
layout(std430, set = 0, binding = 15) writeonly buffer LargeBinBuffer { uvec2 large_bins[]; };
layout(std430, set = 0, binding = 16) buffer LargeTriangleBuffer { LargeTriangle large_triangles[]; };

#define ALPHA_MASK_BINDING 17
#define ALPHA_BOUNDS_CACHE 1
#include "common/alpha_mask.glsl"
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

// Draws the triangle — its corners in pixels, their depths z/w — with visibility id `id`,
// both faces where `both_faces` (else the front alone, as the pipeline culls back faces), the
// pixels `s` keeps; returns the pixels covered.
uint rasterize(vec2 pa, vec2 pb, vec2 pc, vec3 z, uint id, bool both_faces, SurfaceTest s) {
    SmallTriangle t;
    if (!small_triangle(pa, pb, pc, ivec2(frame.viewport.xy), both_faces, t)) {
        return 0u;
    }
    // A masked triangle's texture coordinates: perspective-correct from the edge functions
    // (each corner's weight over its w), as the hardware interpolates; per corner uv/w and 1/w.
    vec3 inv_w = vec3(0.0);
    vec3 u_w = vec3(0.0), v_w = vec3(0.0);
    if (s.masked) {
        inv_w = 1.0 / vec3(s.clip[0].w, s.clip[1].w, s.clip[2].w);
        u_w = vec3(s.uv[0].x, s.uv[1].x, s.uv[2].x) * inv_w;
        v_w = vec3(s.uv[0].y, s.uv[1].y, s.uv[2].y) * inv_w;
    }
    if (t.swapped) {
        // Front faces come swapped: corners b and c.
        z = z.xzy;
        inv_w = inv_w.xzy;
        u_w = u_w.xzy;
        v_w = v_w.xzy;
    }
    uint covered = 0u;
    for (int y = t.first.y; y <= t.last.y; y++) {
        for (int x = t.first.x; x <= t.last.x; x++) {
            ivec3 w;
            if (!small_covers(t, ivec2(x, y), w)) {
                continue;
            }
            float depth = dot(vec3(w), z) / float(t.area);
            vec3 weights = vec3(w);
            if (s.masked && !alpha_kept(s.alpha, s.alpha_texture, vec2(dot(weights, u_w), dot(weights, v_w)) / dot(weights, inv_w))) {
                continue;
            }
            covered++;
            keep_nearest_id(ivec2(x, y), depth, id);
        }
    }
    return covered;
}

// A large triangle (or one crossing the near plane), clipped, into the list of large
// triangles and listed by the bins of its polygon's box; where the lists cannot hold it,
// drawn by this thread. Returns the pixels it covered here.
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
    uint phase = cull.mode.x, capacity = cull.triangles.z;
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
    return raster_polygon_alone(p, id, (flags & INSTANCE_DOUBLE_SIDED) != 0u, s);
}

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

void main() {
    uvec4 d = draw_slots[group_slot()];
    Meshlet m = meshlets[d.w];
    if (gl_LocalInvocationID.x == 0u) {
        group_triangles = 0u;
        group_pixels = 0u;
    }
    transform_meshlet(m, d);
    bool culling = cull.mode.y != 0u;
    uint flags = SURFACE_TESTS ? instances[d.y].meshlets.w : 0u;
    bool both_faces = (flags & INSTANCE_DOUBLE_SIDED) != 0u;
    // Masked: the object's alpha test, the corners' uvs in shared memory (the flags are the
    // work group's: one meshlet, one object).
    SurfaceTest s = no_surface_test();
    if ((flags & INSTANCE_MASKED) != 0u) {
        load_corner_uvs(m, d.y);
        s.masked = true;
        s.alpha = objects[d.y].alpha;
        s.alpha_texture = objects[d.y].alpha_texture;
        cache_alpha_bounds(s.alpha_texture, (s.alpha_texture.x & OBJECT_ALPHA_TEXTURE) != 0u);
    }
    uint triangles = 0u, pixels = 0u;
    for (uint t = gl_LocalInvocationID.x; t < m.triangles.y; t += gl_WorkGroupSize.x) {
        uvec3 v = meshlet_corners(m, t);
        vec4 a = clip[v.x], b = clip[v.y], c = clip[v.z];
        if (culling && !triangle_visible(a, b, c, both_faces)) {
            continue;
        }
        uint id = (d.x << VISIBILITY_TRIANGLE_BITS) | t;
        if (s.masked) {
            s.clip[0] = a;
            s.clip[1] = b;
            s.clip[2] = c;
            s.uv[0] = corner_uv[v.x];
            s.uv[1] = corner_uv[v.y];
            s.uv[2] = corner_uv[v.z];
        }
        uint r = ROUTE_LARGE;
        vec2 pa, pb, pc;
        if (!crosses_near_plane(a, b, c)) {
            pa = framebuffer_xy(a);
            pb = framebuffer_xy(b);
            pc = framebuffer_xy(c);
            r = route(pa, pb, pc);
        }
        if (r == ROUTE_LARGE && cull.triangles.w == 0u) {
            keep_triangle(t);
        } else if (r == ROUTE_LARGE) {
            pixels += list_large(a, b, c, id, flags, d.y, s);
        } else if (r == ROUTE_COMPUTE) {
            vec3 z = vec3(a.z / a.w, b.z / b.w, c.z / c.w);
            pixels += rasterize(pa, pb, pc, z, id, both_faces, s);
            triangles++;
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
