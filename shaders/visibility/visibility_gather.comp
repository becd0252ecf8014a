#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
// The hardware visibility raster's samples (anti-aliasing: its attachments multisampled) into
// the 64-bit buffer the compute raster writes — depth << 32 | id per sample, side by side per
// pixel, all ones where no triangle is — so that the depth pyramid, the light grid's marks and
// the lighting read one layout whichever raster drew. After each phase's draw.
#include "common/common.glsl"
#include "visibility/visibility_samples.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform usampler2DMS visibility_image;
layout(set = 0, binding = 1) uniform sampler2DMS depth_image;
layout(std430, set = 0, binding = 2) writeonly buffer VisibilityDepthBuffer { uint64_t visibility_depth[]; };

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = textureSize(depth_image);
    if (any(greaterThanEqual(p, size))) {
        return;
    }
    for (uint s = 0u; s < VISIBILITY_SAMPLES; s++) {
        float z = texelFetch(depth_image, p, int(s)).r;
        uint id = texelFetch(visibility_image, p, int(s)).r;
        visibility_depth[sample_slot(p, s, uint(size.x))] = z < 1.0 ? (uint64_t(floatBitsToUint(z)) << 32) | uint64_t(id) : ~uint64_t(0);
    }
}
