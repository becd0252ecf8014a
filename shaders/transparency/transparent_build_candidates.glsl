// The transparent layers' build of the objects with cores (blended_cores.glsl), from the
// compute raster's candidates. The raster tests every sample of those objects' triangles for
// their alpha anyway: where it is 1 it draws the core; where it lies between 0 and 1 (and
// the sample in front of what the buffer holds so far) it lists the sample for the layers —
// its pixel and bit, the visibility id and its depth there (layer_candidates.glsl). So a
// core's layers cover what the raster found soft, by the same coverage rule and alpha as the
// core itself. A thread takes a candidate: most lie behind the opaque sample (the raster's
// depth against the finished buffer: the test the listing made against the buffer so far,
// so what is kept does not depend on the order the raster drew in); the others set their
// triangle up from the meshlets — as the per-triangle build sets up its triangles — and keep
// a node of their sample, shaded there. The renderer has the raster list candidates only
// without anti-aliasing: with samples a node each swamped the pool where whole pixels are
// soft (a decal), and joining the samples a pixel listed side by side made renders differ,
// as the list's order does.
//
// Where the raster could not list them all (CullCounters.candidates.y: a core triangle it
// clipped, or the list full) the cores are the per-triangle build's, and this does nothing.
// One dispatch per texture set holding cores (dispatch_objects.x), its work groups striding
// over the list.
#include "common/common.glsl"

layout(local_size_x = 32) in;
const uint BUILD_THREADS = gl_WorkGroupSize.x;
#define LAYER_SLOTS BUILD_THREADS

#include "transparency/layer_triangles.glsl"

// The meshlets' vertex `i` (the same values as the transparent objects' meshes hold).
VERTEX_READER(meshlet_vertex, vertex_data)

void main() {
    if (opaque_uniform(counters.candidates.y) != 0u) {
        return;
    }
    uint lid = gl_LocalInvocationIndex;
    uint set = opaque_uniform(dispatch_objects.x);
    uint count = min(opaque_uniform(counters.candidates.x), uint(layer_candidates.length()));
    vec2 to_ndc = 2.0 / vec2(frame.viewport.xy);
    uint capacity = layer_capacity();
    for (uint base = gl_WorkGroupID.x * BUILD_THREADS; base < count; base += gl_NumWorkGroups.x * BUILD_THREADS) {
        uint at = base + lid;
        bool found = false;
        ivec2 p = ivec2(0);
        uint listed = 0u;
        if (at < count) {
            uvec4 c = layer_candidates[at];
            p = ivec2(c.x & 0xffffu, c.x >> 16);
            listed = c.w;
            if (uintBitsToFloat(c.z) < opaque_depth_of_sample(p, uint(findLSB(c.w)))) {
                uvec2 object_meshlet = meshlet_instances[c.y >> VISIBILITY_TRIANGLE_BITS];
                uvec4 surface = instances[object_meshlet.x].surface;
                if (surface.y == set) {
                    uvec3 v = meshlet_triangle(meshlets[object_meshlet.y], c.y & ((1u << VISIBILITY_TRIANGLE_BITS) - 1u));
                    Vtx corners[3] = Vtx[3](meshlet_vertex(v.x), meshlet_vertex(v.y), meshlet_vertex(v.z));
                    ivec4 box;
                    set_up_corners(lid, uvec2(object_meshlet.x, surface.x), corners, box);
                    vec3 q, w;
                    float depth, alpha;
                    uint covered;
                    found = layer_fragment_of(lid, p, to_ndc, opaque_depth_at(p), listed, q, covered, w, depth, alpha);
                }
            }
        }
        uint node = take_nodes(found ? 1u : 0u);
        if (found) {
            keep_fragment_of(lid, p, node, capacity, to_ndc, listed);
        }
    }
}
