#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
// The compute raster's large triangles, drawn by the hardware (visibility.vert, the phase's
// indexed draw) into the compute raster's buffer: per fragment the same 64-bit atomic min of
// depth << 32 | visibility id that triangle_raster.comp does, so both write one visibility
// buffer in one frame. No attachments: the atomic is the depth test. Depth 1 is the far
// plane, which LESS against the cleared depth never lets through.
#ifndef MANYLIGHTS_VISIBILITY_ATOMIC_FRAG_GLSL
#define MANYLIGHTS_VISIBILITY_ATOMIC_FRAG_GLSL

#include "common/common.glsl"
#include "visibility/visibility_surface.glsl"

layout(std430, set = 0, binding = 5) readonly buffer TriangleIdBuffer { uint triangle_ids[]; };
layout(std430, set = 0, binding = 6) buffer VisibilityDepthBuffer { uint64_t visibility_depth[]; };
layout(push_constant) uniform RasterPushBlock { uvec4 first_id; }; // x: this phase's first id; y: image width

void main() {
    float depth = gl_FragCoord.z;
    if (depth >= 1.0 || !surface_there()) {
        return;
    }
    uint id = triangle_ids[first_id.x + uint(gl_PrimitiveID)];
    uvec2 p = uvec2(gl_FragCoord.xy);
    atomicMin(visibility_depth[p.y * first_id.y + p.x], (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(id));
}

#endif
