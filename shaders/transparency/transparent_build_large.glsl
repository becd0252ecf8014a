// The transparent layers' build of the triangles too large for a thread of the per-triangle
// build (transparent_build_triangles.glsl), which lists them: a work group each, its threads
// a 16×16 block stepped over the triangle's box (at most GROUP_BOX, 256 pixels, a side: 256
// steps), marking where they find fragments, then taking room for all of them at once. The work groups (as many as that build
// counted, at most 65,535) stride through the list.
//
// The includer defines OPAQUE_DEPTH_BUFFER for the compute raster's 64-bit buffer.
#include "common/common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;

#define LAYER_SLOTS 1u
#include "transparency/layer_triangles.glsl"

shared ivec4 group_box;

void main() {
    uint lid = gl_LocalInvocationIndex;
    uint slot = opaque_uniform(dispatch_objects.w) - 1u, first = opaque_uniform(large_list.x);
    uint listed = large_triangles[LIST_WORDS * slot + LIST_LARGE];
    vec2 to_ndc = 2.0 / vec2(frame.viewport.xy);
    uint capacity = layer_capacity();
    for (uint i = gl_WorkGroupID.x; i < listed; i += gl_NumWorkGroups.x) {
        if (lid == 0u) {
            set_up_triangle(0u, layer_objects[first + i], 0u, group_box);
        }
        barrier();
        ivec4 box = group_box;
        // The blocks where this thread's pixel has a fragment, a bit each ((GROUP_BOX / 16)²
        // at most), then room for all of the work group's, then their nodes.
        int columns = (box.z - box.x + 16) / 16, blocks = columns * ((box.w - box.y + 16) / 16);
        uint hits[GROUP_BLOCK_WORDS];
        for (uint k = 0u; k < GROUP_BLOCK_WORDS; k++) {
            hits[k] = 0u;
        }
        uint mine = 0u;
        for (int b = 0; b < blocks; b++) {
            ivec2 p = box.xy + 16 * ivec2(b % columns, b / columns) + ivec2(gl_LocalInvocationID.xy);
            if (all(lessThanEqual(p, box.zw)) && pixel_fragment(0u, p, to_ndc)) {
                hits[b >> 5] |= 1u << (b & 31);
                mine++;
            }
        }
        uint node = take_nodes(mine);
        for (uint k = 0u; k < GROUP_BLOCK_WORDS && mine > 0u; k++) {
            for (uint bits = hits[k]; bits != 0u; bits &= bits - 1u) {
                int b = int(32u * k) + findLSB(bits);
                keep_fragment(0u, box.xy + 16 * ivec2(b % columns, b / columns) + ivec2(gl_LocalInvocationID.xy), node++, capacity, to_ndc);
            }
        }
        // Before the next triangle's set-up.
        barrier();
    }
}
