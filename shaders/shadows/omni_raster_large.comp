#version 450
#extension GL_GOOGLE_include_directive : require
// The compute shadow raster, step 3 (omni_raster.glsl): a work group per large triangle (or
// one crossing the near plane), its clipped polygon set up once. Its fan triangles are drawn
// one after the other, a thread per 8×8-texel tile of the box: a tile the triangle does not
// reach (tested against the three edges at its corners) costs one test, so the work follows
// the texels covered more than the box.
#include "common/common.glsl"

layout(local_size_x = 256) in;

#include "shadows/omni_raster.glsl"

const int TILE = 8;

// The triangle's clipped polygon, set up once by the first thread.
shared ivec2 corner_s[MAX_POLYGON];
shared vec4 corner_q[MAX_POLYGON];
shared int corner_count;
// Its surface test (raster_surface.glsl), also set up by the first thread.
shared bool corner_masked;
shared vec4 corner_clip[3];
shared vec2 corner_uv[3];

void main() {
    uint lid = gl_LocalInvocationID.x;
    uint count = min(counters.large.w, opaque_uniform(omni.capacity.y));
    uint covered = 0u;
    for (uint e = gl_WorkGroupID.x; e < count; e += gl_NumWorkGroups.x) {
        // The last triangle's threads are done with the polygon.
        barrier();
        if (lid == 0u) {
            uvec2 listed = large_triangles[e];
            uvec2 pair = pairs[listed.x];
            uvec2 object_meshlet = meshlet_instances[pair.x];
            Meshlet m = meshlets[object_meshlet.y];
            mat4 model = objects[object_meshlet.x].model;
            uvec3 v = meshlet_triangle(m, listed.y);
            vec4 a, b, c;
            vec3 ra = view_vertex(v.x, model, pair.y, a), rb = view_vertex(v.y, model, pair.y, b), rc = view_vertex(v.z, model, pair.y, c);
            Polygon p = clipped_polygon(a, b, c, ra, rb, rc, vec2(float(view_side(pair.y))));
            corner_count = p.count;
            SurfaceTest s = omni_surface_test(object_meshlet.x, v, a, b, c);
            corner_masked = s.masked;
            for (int i = 0; i < 3; i++) {
                corner_clip[i] = s.clip[i];
                corner_uv[i] = s.uv[i];
            }
            for (int i = 0; i < p.count; i++) {
                corner_s[i] = ivec2(p.s[i]);
                corner_q[i] = p.q[i];
            }
        }
        barrier();
        uint layer = pairs[large_triangles[e].x].y;
        SurfaceTest s = no_surface_test();
        // MASK_TESTS first: a flag read back from shared memory does not fold away, and the
        // masked path's registers would cost every scene's texel loop.
        if (MASK_TESTS && corner_masked) {
            uint object = meshlet_instances[pairs[large_triangles[e].x].x].x;
            s = masked_surface(objects[object].alpha, objects[object].alpha_texture, corner_clip[0], corner_clip[1], corner_clip[2],
                               corner_uv[0], corner_uv[1], corner_uv[2]);
        }
        ivec2 side = ivec2(view_side(layer));
        int corners = corner_count;
        for (int k = 1; k + 1 < corners; k++) {
            FanTriangle t;
            i64vec2 a = i64vec2(corner_s[0]), b = i64vec2(corner_s[k]), c = i64vec2(corner_s[k + 1]);
            if (!fan_triangle(a, b, c, corner_q[0], corner_q[k], corner_q[k + 1], side, true, t)) {
                continue;
            }
            ivec2 tile0 = t.first / TILE;
            uvec2 span = uvec2(t.last / TILE - tile0 + 1);
            for (uint i = lid; i < span.x * span.y; i += gl_WorkGroupSize.x) {
                ivec2 lo = max((tile0 + ivec2(i % span.x, i / span.x)) * TILE, t.first);
                ivec2 hi = min(lo - lo % TILE + TILE - 1, t.last);
                if (!fan_reaches(t, lo, hi)) {
                    continue;
                }
                for (int y = lo.y; y <= hi.y; y++) {
                    for (int x = lo.x; x <= hi.x; x++) {
                        covered += fan_texel(t, ivec2(x, y), layer, s);
                    }
                }
            }
        }
    }
    atomicAdd(counters.drawn.z, covered);
}
