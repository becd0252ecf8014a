// The visibility buffer: per pixel one 32-bit id, the meshlet instance (high 25 bits) and the
// triangle in its meshlet (low 7 bits), which the triangle culling stored per compacted
// triangle: gl_PrimitiveID counts this phase's draw's triangles from 0. Depth is the depth
// attachment's.
#ifndef MANYLIGHTS_VISIBILITY_FRAG_GLSL
#define MANYLIGHTS_VISIBILITY_FRAG_GLSL

#include "common/common.glsl"
#include "visibility/visibility_surface.glsl"

layout(std430, set = 0, binding = 5) readonly buffer TriangleIdBuffer { uint triangle_ids[]; };
layout(push_constant) uniform RasterPushBlock { uvec4 first_id; }; // x: this phase's first id

layout(location = 0) out uint out_id;

void main() {
    if (!surface_there()) {
        discard;
    }
    out_id = triangle_ids[first_id.x + uint(gl_PrimitiveID)];
}

#endif
