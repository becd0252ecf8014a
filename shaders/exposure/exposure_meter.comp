#version 450
#extension GL_GOOGLE_include_directive : require
// Auto exposure's meter (docs/DESIGN.md#exposure): after the frame is shaded, the 8-bit image
// is read back into the linear luminance each pixel had before exposure — gamma undone, pbr's
// tone map undone, divided by the exposure the frame used — and each 8×8 work group writes
// the sum of log2 luminance over its pixels and how many it metered. The CPU adds the groups
// up in order (the same sum every run) and sets the next frame's EV from the log-average.
// Every technique writes this image, so one meter serves them all. Pixels showing the
// background colour are not metered; clipped ones read low, which the next frame (or the
// render's repeat of its last) corrects.
#include "common/common.glsl"
#include "common/shading_model.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba8) uniform readonly image2D out_image;
FRAME_BLOCK(1);
// Per work group (row by row): x, the sum of log2 luminance; y, the pixels metered.
layout(std430, set = 0, binding = 2) writeonly buffer ExposureMeterBuffer { vec2 group_sums[]; };

// The darkest luminance metered: a black pixel counts as this (log2: about −13).
const float FLOOR = 1.0e-4;

shared vec2 sums[64];

// aces_tone_map's inverse on [0, 1): the root in x ≥ 0 of
// y·(2.43x² + 0.59x + 0.14) = 2.51x² + 0.03x.
vec3 inverse_aces(vec3 y) {
    y = min(y, vec3(0.99));
    vec3 a = 2.51 - 2.43 * y, b = 0.03 - 0.59 * y, c = -0.14 * y;
    return (-b + sqrt(b * b - 4.0 * a * c)) / (2.0 * a);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    vec2 mine = vec2(0.0);
    if (all(lessThan(p, imageSize(out_image)))) {
        vec3 stored = imageLoad(out_image, p).rgb;
        bool background = all(equal(round(stored * 255.0), round(CLEAR_COLOR.rgb * 255.0)));
        if (!background) {
            vec3 linear = pow(stored, vec3(2.2));
            if (MODEL_PBR) {
                linear = inverse_aces(linear);
            }
            float luminance = dot(linear, vec3(0.2126, 0.7152, 0.0722)) / frame.exposure.x;
            mine = vec2(log2(max(luminance, FLOOR)), 1.0);
        }
    }
    uint lid = gl_LocalInvocationIndex;
    sums[lid] = mine;
    for (uint half_size = 32u; half_size > 0u; half_size >>= 1u) {
        barrier();
        if (lid < half_size) {
            sums[lid] += sums[lid + half_size];
        }
    }
    if (lid == 0u) {
        group_sums[gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x] = sums[0];
    }
}
