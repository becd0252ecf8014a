#version 450
#extension GL_GOOGLE_include_directive : require
// The environment's diffuse light as nine spherical-harmonic coefficients: one work group
// projects every texel of a small level of the cube (each weighted by its solid angle), sums
// the threads' parts in a fixed order (the same coefficients every run) and applies the
// clamped cosine's convolution over π (ml_cpu::environment::SH9_LAMBERT).
#include "common/common.glsl"
#include "environment/environment_maps.glsl"

layout(local_size_x = 256, local_size_y = 1, local_size_z = 1) in;

layout(set = 0, binding = 0, rgba16f) uniform readonly image2DArray sh_level;
layout(std430, set = 0, binding = 1) buffer EnvironmentBuffer { EnvironmentData environment; };

shared vec3 partial[256];

const float LAMBERT[9] = float[](1.0, 2.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0, 0.25, 0.25, 0.25, 0.25, 0.25);

void main() {
    uint thread = gl_LocalInvocationID.x;
    int size = imageSize(sh_level).x;
    int texels = size * size * 6;
    vec3 sum[9];
    for (int k = 0; k < 9; ++k) {
        sum[k] = vec3(0.0);
    }
    for (int i = int(thread); i < texels; i += 256) {
        int face = i / (size * size);
        ivec2 xy = ivec2(i % size, (i / size) % size);
        vec2 uv = (vec2(xy) + 0.5) / float(size);
        vec3 d = cube_direction(face, uv);
        // A texel's solid angle: its area on the unit cube (2/size)² over |d|³.
        float solid_angle = 4.0 / (float(size * size) * pow(dot(d, d), 1.5));
        vec3 radiance = imageLoad(sh_level, ivec3(xy, face)).rgb * solid_angle;
        float y[9];
        sh9_basis(normalize(d), y);
        for (int k = 0; k < 9; ++k) {
            sum[k] += radiance * y[k];
        }
    }
    for (int k = 0; k < 9; ++k) {
        partial[thread] = sum[k];
        barrier();
        for (uint stride = 128u; stride > 0u; stride >>= 1) {
            if (thread < stride) {
                partial[thread] += partial[thread + stride];
            }
            barrier();
        }
        if (thread == 0u) {
            environment.sh[k] = vec4(partial[0] * LAMBERT[k], 0.0);
        }
        barrier();
    }
}
