#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
// The compute raster's large triangles, drawn by the hardware (visibility.vert, the phase's
// indexed draw) into the compute raster's buffer: per fragment the same 64-bit atomic min of
// depth << 32 | visibility id that triangle_raster.comp does, so both write one visibility
// buffer in one frame. No attachments: the atomic is the depth test. Depth 1 is the far
// plane, which LESS against the cleared depth never lets through. With anti-aliasing's
// samples (the pipeline multisampled, no attachments) the fragment writes each sample it
// covers, at the depth its triangle has there and, with masks, where the alpha at the
// sample's texture coordinates keeps it — as the compute raster's paths test each sample.
#ifndef MANYLIGHTS_VISIBILITY_ATOMIC_FRAG_GLSL
#define MANYLIGHTS_VISIBILITY_ATOMIC_FRAG_GLSL

#include "common/common.glsl"
#include "visibility/visibility_surface.glsl"
#include "visibility/visibility_samples.glsl"

layout(std430, set = 0, binding = 5) readonly buffer TriangleIdBuffer { uint triangle_ids[]; };
layout(std430, set = 0, binding = 6) buffer VisibilityDepthBuffer { uint64_t visibility_depth[]; };
layout(push_constant) uniform RasterPushBlock { uvec4 first_id; }; // x: this phase's first id; y: image width

void main() {
    float depth = gl_FragCoord.z;
    // Before any branch: derivatives need the whole quad.
    vec2 depth_d = vec2(dFdx(depth), dFdy(depth));
#ifdef SURFACE_TESTS
    mat2 uv_d = mat2(dFdx(in_uv), dFdy(in_uv));
#endif
    uint id = triangle_ids[first_id.x + uint(gl_PrimitiveID)];
    ivec2 p = ivec2(gl_FragCoord.xy);
    if (VISIBILITY_SAMPLES == 1u) {
        if (depth >= 1.0 || !surface_there()) {
            return;
        }
        atomicMin(visibility_depth[p.y * int(first_id.y) + p.x], (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(id));
        return;
    }
    if (!side_drawn()) {
        return;
    }
    for (uint s = 0u; s < VISIBILITY_SAMPLES; s++) {
        vec2 step = sample_step(s);
        // The plane's depth at the sample (never below the near plane's 0: the sign bit would
        // make it the farthest).
        float z = max(depth + dot(depth_d, step), 0.0);
        bool there = (gl_SampleMaskIn[0] & (1 << s)) != 0 && z < 1.0;
#ifdef SURFACE_TESTS
        there = there && point_there(in_uv + uv_d * step);
#endif
        if (there) {
            atomicMin(visibility_depth[sample_slot(p, s, first_id.y)], (uint64_t(floatBitsToUint(z)) << 32) | uint64_t(id));
        }
    }
}

#endif
