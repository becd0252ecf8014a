// The visibility buffer: per pixel one 32-bit id, the meshlet instance (high 25 bits) and the
// triangle in its meshlet (low 7 bits), which the triangle culling stored per compacted
// triangle: gl_PrimitiveID counts this phase's draw's triangles from 0. Depth is the depth
// attachment's.
#ifndef MANYLIGHTS_VISIBILITY_FRAG_GLSL
#define MANYLIGHTS_VISIBILITY_FRAG_GLSL

#include "common/common.glsl"
#include "visibility/visibility_surface.glsl"
#include "visibility/visibility_samples.glsl"

layout(std430, set = 0, binding = 5) readonly buffer TriangleIdBuffer { uint triangle_ids[]; };
layout(push_constant) uniform RasterPushBlock { uvec4 first_id; }; // x: this phase's first id

layout(location = 0) out uint out_id;

// With anti-aliasing's samples (multisampled attachments) a masked surface is tested at each
// sample's texture coordinates and keeps the samples where it is (the sample mask, written
// on every path: a shader that writes it anywhere leaves it undefined where it does not).
void main() {
#ifdef SURFACE_TESTS
    // Before any branch: derivatives need the whole quad.
    mat2 uv_d = mat2(dFdx(in_uv), dFdy(in_uv));
#endif
    int kept = -1;
    if (VISIBILITY_SAMPLES == 1u) {
        if (!surface_there()) {
            discard;
        }
    } else {
        if (!side_drawn()) {
            discard;
        }
#ifdef SURFACE_TESTS
        kept = 0;
        for (uint s = 0u; s < VISIBILITY_SAMPLES; s++) {
            vec2 uv = in_uv + uv_d * sample_step(s);
            if ((gl_SampleMaskIn[0] & (1 << s)) != 0 && point_there(uv)) {
                kept |= 1 << s;
            }
        }
        if (kept == 0) {
            discard;
        }
#endif
    }
    gl_SampleMask[0] = kept;
    out_id = triangle_ids[first_id.x + uint(gl_PrimitiveID)];
}

#endif
