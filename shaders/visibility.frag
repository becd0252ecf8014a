#version 450
#extension GL_GOOGLE_include_directive : require
// The visibility buffer: per pixel one 32-bit id, the meshlet instance (high 25 bits) and the
// triangle in its meshlet (low 7 bits: gl_PrimitiveID counts from 0 in every draw, and a draw
// is one meshlet of ≤ 124 triangles). Depth is the depth attachment's.
#include "common.glsl"

layout(location = 0) flat in uint in_meshlet_instance;
layout(location = 0) out uint out_id;

void main() {
    out_id = (in_meshlet_instance << VISIBILITY_TRIANGLE_BITS) | uint(gl_PrimitiveID);
}
