#version 450
#extension GL_GOOGLE_include_directive : require
// The compute shadow raster, step 2 (omni_raster.glsl): a work group per listed (meshlet
// instance, cube face) pair, the meshlet's vertices transformed once into shared memory, a
// thread per triangle. Small triangles wholly beyond the near plane are drawn here; the
// others are listed for step 3 (a work group each), or drawn here if that list is full.
#include "common/common.glsl"

layout(local_size_x = 64) in;

#include "shadows/omni_raster.glsl"

shared vec4 corner_clip[64];
shared vec3 corner_rel[64];

void main() {
    uint lid = gl_LocalInvocationID.x;
    uint pair_count = min(counters.pairs.w, opaque_uniform(omni.capacity.x));
    uint small = 0u, in_place = 0u, covered = 0u;
    for (uint e = gl_WorkGroupID.x; e < pair_count; e += gl_NumWorkGroups.x) {
        uvec2 pair = pairs[e];
        uvec2 object_meshlet = meshlet_instances[pair.x];
        Meshlet m = meshlets[object_meshlet.y];
        uint layer = pair.y;
        // The last pair's triangles are done with the shared corners.
        barrier();
        if (lid < m.triangles.w) {
            vec4 clip;
            corner_rel[lid] = view_vertex(meshlet_vertices[m.triangles.z + lid], objects[object_meshlet.x].model, layer, clip);
            corner_clip[lid] = clip;
        }
        barrier();
        for (uint t = lid; t < m.triangles.y; t += gl_WorkGroupSize.x) {
            uvec3 v = meshlet_corners(m, t);
            vec4 a = corner_clip[v.x], b = corner_clip[v.y], c = corner_clip[v.z];
            if (outside_face(a, b, c)) {
                continue;
            }
            vec3 ra = corner_rel[v.x], rb = corner_rel[v.y], rc = corner_rel[v.z];
            SurfaceTest s = omni_surface_test(object_meshlet.x, meshlet_triangle(m, t), a, b, c);
            if (a.z >= 0.0 && b.z >= 0.0 && c.z >= 0.0) {
                vec2 pa = face_xy(a, layer), pb = face_xy(b, layer), pc = face_xy(c, layer);
                vec2 box = max(pa, max(pb, pc)) - min(pa, min(pb, pc));
                if (all(lessThanEqual(box, vec2(float(opaque_uniform(omni.sizes.z)))))) {
                    covered += raster_small(pa, pb, pc, vec4(ra, 1.0 / a.w), vec4(rb, 1.0 / b.w), vec4(rc, 1.0 / c.w), layer, s);
                    small++;
                    continue;
                }
            }
            uint at = atomicAdd(counters.large.w, 1u);
            if (at < omni.capacity.y) {
                atomicMax(counters.large.x, min(at + 1u, MAX_GROUPS));
                large_triangles[at] = uvec2(e, t);
            } else {
                covered += raster_large_alone(a, b, c, ra, rb, rc, layer, s);
                in_place++;
            }
        }
    }
    atomicAdd(counters.drawn.x, small + in_place);
    atomicAdd(counters.drawn.y, in_place);
    atomicAdd(counters.drawn.z, covered);
}
