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
// triangle (large, or crossing the near plane, which the hardware clips) goes to the phase's
// indexed draw, whose fragments do the same atomic min into the same buffer.
#include "common.glsl"

layout(local_size_x = 64) in;

#include "meshlet_cull.glsl"
#include "meshlet_geometry.glsl"
#include "triangle_cull.glsl"
#include "raster_rules.glsl"

// Per pixel, row by row: floatBitsToUint(depth) << 32 | visibility id, the nearest kept; all
// ones where nothing was drawn (visibility_resolve.comp makes the two images of it).
layout(std430, set = 0, binding = 14) buffer VisibilityDepthBuffer { uint64_t visibility_depth[]; };

const uint ROUTE_NONE = 0u;     // no pixel to draw
const uint ROUTE_COMPUTE = 1u;  // drawn here
const uint ROUTE_HARDWARE = 2u; // appended to the indexed draw

shared uint group_triangles;
shared uint group_pixels;

// The viewport transform (xf = width/2 · x/w + width/2, y likewise), in pixels.
vec2 framebuffer_xy(vec4 c) {
    vec2 half_size = vec2(frame.viewport.xy) * 0.5;
    return c.xy / c.w * half_size + half_size;
}

// In front of the near plane (or behind the eye) somewhere: the hardware clips it.
bool crosses_near_plane(vec4 a, vec4 b, vec4 c) {
    return a.z < 0.0 || b.z < 0.0 || c.z < 0.0 || a.w <= 0.0 || b.w <= 0.0 || c.w <= 0.0;
}

// Where a triangle wholly beyond the near plane is drawn, from its corners in pixels.
uint route(vec2 pa, vec2 pb, vec2 pc) {
    vec2 lo = min(pa, min(pb, pc)), hi = max(pa, max(pb, pc));
    if (any(greaterThan(hi - lo, vec2(float(cull.triangles.y))))) {
        return ROUTE_HARDWARE;
    }
    // Off screen, with a pixel of margin for the snapping.
    if (any(lessThan(hi, vec2(-1.0))) || any(greaterThan(lo, vec2(frame.viewport.xy) + 1.0))) {
        return ROUTE_NONE;
    }
    return ROUTE_COMPUTE;
}

// Draws the triangle — its corners in pixels, their depths z/w — with visibility id `id`;
// returns the pixels covered.
uint rasterize(vec2 pa, vec2 pb, vec2 pc, vec3 z, uint id) {
    // The pipeline culls back faces.
    SmallTriangle t;
    if (!small_triangle(pa, pb, pc, ivec2(frame.viewport.xy), false, t)) {
        return 0u;
    }
    z = z.xzy; // front faces come swapped
    uint covered = 0u;
    for (int y = t.first.y; y <= t.last.y; y++) {
        for (int x = t.first.x; x <= t.last.x; x++) {
            ivec3 w;
            if (!small_covers(t, ivec2(x, y), w)) {
                continue;
            }
            covered++;
            float depth = dot(vec3(w), z) / float(t.area);
            if (depth >= 1.0) {
                continue;
            }
            uint64_t value = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(id);
            atomicMin(visibility_depth[uint(y) * frame.viewport.x + uint(x)], value);
        }
    }
    return covered;
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
    uint triangles = 0u, pixels = 0u;
    for (uint t = gl_LocalInvocationID.x; t < m.triangles.y; t += gl_WorkGroupSize.x) {
        uvec3 v = meshlet_corners(m, t);
        vec4 a = clip[v.x], b = clip[v.y], c = clip[v.z];
        if (culling && !triangle_visible(a, b, c)) {
            continue;
        }
        if (crosses_near_plane(a, b, c)) {
            keep_triangle(t);
            continue;
        }
        vec2 pa = framebuffer_xy(a), pb = framebuffer_xy(b), pc = framebuffer_xy(c);
        uint r = route(pa, pb, pc);
        if (r == ROUTE_HARDWARE) {
            keep_triangle(t);
        } else if (r == ROUTE_COMPUTE) {
            vec3 z = vec3(a.z / a.w, b.z / b.w, c.z / c.w);
            pixels += rasterize(pa, pb, pc, z, (d.x << VISIBILITY_TRIANGLE_BITS) | t);
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
