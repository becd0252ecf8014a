#version 450
#extension GL_GOOGLE_include_directive : require
// Culling, step 3, a work group per meshlet drawn in this phase (docs/DESIGN.md#gpu-culling):
// its vertices transformed once into shared memory, then every triangle tested as the
// rasteriser would see it — back-facing, or covering no pixel centre (too small, between
// centres, or off screen), or wholly in front of the near or beyond the far plane — and the
// survivors appended, in their meshlet's order, to the compacted index buffer that the raster
// draws with one indexed draw per phase. Triangles crossing the eye's plane are kept (the
// rasteriser clips them). Culling off keeps every triangle.
#include "common/common.glsl"

layout(local_size_x = 64) in;

#include "visibility/meshlet_cull.glsl"
#include "visibility/meshlet_geometry.glsl"
// With anti-aliasing's samples (the hardware raster multisampled) a triangle that misses
// every centre may still cover a sample.
#include "visibility/visibility_samples.glsl"
#include "visibility/triangle_cull.glsl"

void main() {
    uvec4 d = draw_slots[group_slot()];
    Meshlet m = meshlets[d.w];
    transform_meshlet(m, d);
    bool culling = opaque_uniform(cull.mode.y) != 0u;
    bool both_faces = (instances[d.y].meshlets.w & INSTANCE_DOUBLE_SIDED) != 0u;
    for (uint t = gl_LocalInvocationID.x; t < m.triangles.y; t += gl_WorkGroupSize.x) {
        uvec3 v = meshlet_corners(m, t);
        if (!culling || triangle_visible(clip[v.x], clip[v.y], clip[v.z], both_faces)) {
            keep_triangle(t);
        }
    }
    append_kept(m, d);
}
