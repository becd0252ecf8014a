// The compute-vs-fragment probe (stage_probe.rs): one BRDF loop — the seed model's point
// light, the function every shading path calls — summed over every light for each pixel of
// a synthetic floor, run once as a fragment shader and once as a compute shader over the same
// pixels. The ratio of their times says which kind of pass a device shades faster (the
// H100/H200 run graphics shaders on 4 of 132 SMs). The lights reach every pixel, so no pixel
// skips work and both stages do exactly the same arithmetic.

#ifndef MANYLIGHTS_STAGE_PROBE_GLSL
#define MANYLIGHTS_STAGE_PROBE_GLSL

#include "common/common.glsl"
#include "common/seed_brdf.glsl"

layout(push_constant) uniform StageProbeBlock {
    StageProbePush probe;
};
layout(std430, set = 0, binding = 0) readonly buffer ProbeLights {
    PointLight probe_lights[];
};

// Pixel `p` of a 40 m × 40 m gold floor (roughness 0.3) seen from (0, 15, 25): the sum of every light, tone-mapped
// x / (1 + x) so that both stages store the same 8-bit values (the test compares them).
vec4 probe_pixel(ivec2 p) {
    vec2 uv = (vec2(p) + 0.5) / vec2(probe.size_lights.xy);
    vec3 world = vec3(uv.x * 40.0 - 20.0, 0.0, uv.y * 40.0 - 20.0);
    vec3 n = vec3(0.0, 1.0, 0.0);
    vec3 v = normalize(vec3(0.0, 15.0, 25.0) - world);
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < opaque_uniform(probe.size_lights.z); ++i) {
        sum += seed_point_light(probe_lights[i], world, n, v, vec3(1.0, 0.765557, 0.336057), 0.3, 1.0);
    }
    return vec4(sum / (1.0 + sum), 1.0);
}

#endif
