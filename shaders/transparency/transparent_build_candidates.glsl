// The transparent layers' build of the objects with cores (blended_cores.glsl), from the
// compute raster's candidates. The raster tests every sample of those objects' triangles for
// their alpha anyway: where it is 1 it draws the core; where it lies between 0 and 1 (and
// the sample in front of what the buffer holds so far) it lists the sample for the layers —
// its pixel and bit, the visibility id and the triangle's nearest corner's depth
// (layer_candidates.glsl). So a core's layers cover what the raster found soft, by the same
// coverage rule and alpha as the core itself. A pixel's samples of one triangle are mostly
// listed side by side: such a run is one candidate, taken by the thread of its first. Most
// fail one read of the opaque samples (something opaque nearer than the triangle's nearest
// corner at each); the others set the triangle up from the meshlets — as the per-triangle
// build sets up its triangles — and keep their samples in front of the opaque ones, shaded
// once at the pixel. (A run split apart makes fragments of disjoint samples: right, a
// little more work.)
// Where the per-triangle build walked every triangle of the forest of a million leaves again
// after the raster (1.04 ms on the H200 at 1080p for some 20,000 fragments), this reads
// about 40,000 candidates.
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

// Whether candidate `c` may leave a fragment: at some sample it lists the opaque surface lies
// behind its triangle's nearest corner (the fragments' depths lie between the corners' up to
// their rounding, which 2^-20 covers).
bool may_leave_fragment(uvec4 c) {
    ivec2 p = ivec2(c.x & 0xffffu, c.x >> 16);
    float nearest = uintBitsToFloat(c.z) - 1.0 / 1048576.0;
    bool may = false;
    for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
        may = may || ((c.w & (1u << k)) != 0u && opaque_depth_of_sample(p, k) > nearest);
    }
    return may;
}

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
            bool first = at == 0u || any(notEqual(layer_candidates[at - 1u].xy, c.xy));
            for (uint j = at + 1u; first && j < min(count, at + VISIBILITY_SAMPLES); j++) {
                uvec4 next = layer_candidates[j];
                if (any(notEqual(next.xy, c.xy))) {
                    break;
                }
                c.w |= next.w;
            }
            p = ivec2(c.x & 0xffffu, c.x >> 16);
            listed = c.w;
            if (first && may_leave_fragment(c)) {
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
