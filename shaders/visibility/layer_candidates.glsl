// The compute raster's candidates for the transparent layers (transparent_build_candidates.glsl):
// where it tests a sample of a transparent object with a core (blended_cores.glsl) and finds
// its alpha between 0 and 1 — not the core's, not cut out — in front of what the buffer
// holds so far, it lists the sample: its pixel, its bit, the visibility id and its depth.
// Both compute rasters include it (the small triangles' and the large ones'); the includer
// declares `counters` (CullCounterBuffer), `visibility_depth` (uint64_t) and
// LAYER_CANDIDATE_BINDING, and includes alpha_mask.glsl and blended_cores.glsl first.

#ifndef MANYLIGHTS_LAYER_CANDIDATES_GLSL
#define MANYLIGHTS_LAYER_CANDIDATES_GLSL
#extension GL_KHR_shader_subgroup_ballot : require
#include "visibility/visibility_samples.glsl"

// Whether this raster lists candidates (the compute raster with layers and cores).
layout(constant_id = 26) const bool LAYER_CANDIDATES = false;
// (pixel y << 16 | x, visibility id, the sample's depth, its bit) each.
layout(std430, set = 0, binding = LAYER_CANDIDATE_BINDING) writeonly buffer LayerCandidateBuffer { uvec4 layer_candidates[]; };

// Whether the object of ObjectData alpha_texture.x `flags` has its cores' layers listed here.
bool lists_candidates(uint flags) {
    return LAYER_CANDIDATES && (flags & OBJECT_CORE) != 0u;
}

// From here the cores are the per-triangle build's this frame (a triangle this raster
// cannot list: one it clipped, or drew in place).
void leave_cores_to_the_triangles() {
    atomicMax(counters.candidates.y, 1u);
}

// Whether sample k of `pixel`, covered at `depth` by a core's triangle whose alpha there
// (`alpha`, as the raster's test finds it) is below 1, is soft: alpha above 0, in front of
// what the buffer holds.
bool soft_in_front(float alpha, ivec2 pixel, uint k, float depth) {
    if (alpha <= 0.0) {
        return false;
    }
    // (Read while other threads' atomics may lower it: any value it held this frame is no
    // nearer than the finished buffer's, against which the candidates' build decides.)
    uvec2 there = unpack32(visibility_depth[sample_slot(pixel, k, frame.viewport.x)]);
    return depth < visibility_buffer_depth(there);
}

// What a core's sample is, from the bounds of its texture block (one read, as alpha_verdict):
// its core (alpha 1: drawn), cut out (0), soft for certain, or filter it to tell.
const uint CORE_SAMPLE = 0u;
const uint CLEAR_SAMPLE = 1u;
const uint SOFT_SAMPLE = 2u;
const uint FILTER_SAMPLE = 3u;
uint core_sample_verdict(vec4 alpha, uvec4 alpha_texture, vec2 uv) {
    vec2 bounds = vec2(1.0);
    if ((alpha_texture.x & OBJECT_ALPHA_TEXTURE) != 0u) {
        uint pair = texture_bounds_at(alpha_texture, uv);
        bounds = vec2(pair & 0xffu, (pair >> 8u) & 0xffu) / 255.0;
    }
    bounds *= alpha.y;
    if (bounds.x >= 1.0) {
        return CORE_SAMPLE;
    }
    if (bounds.y <= 0.0) {
        return CLEAR_SAMPLE;
    }
    return bounds.x > 0.0 && bounds.y < 1.0 ? SOFT_SAMPLE : FILTER_SAMPLE;
}

// A core's alpha at `uv` as far as the raster needs it, from its sample's `verdict`: 1
// (drawn), 0 (cut out), else between (0.5 where the bounds say so unfiltered).
float core_sample_alpha(vec4 alpha, uvec4 alpha_texture, vec2 uv, uint verdict) {
    if (verdict == FILTER_SAMPLE) {
        return alpha.y * texture_alpha(alpha_texture, uv);
    }
    return verdict == CORE_SAMPLE ? 1.0 : verdict == CLEAR_SAMPLE ? 0.0 : 0.5;
}

// Candidate `c` (layer_candidate) listed where `soft`: the lanes here together take their
// room with one atomic. The small triangles' raster calls it in every lane at every sample
// of a core (on the H200 the forest's raster took 0.81 ms so, 1.01 called by the soft lanes
// alone; at 8 samples 4.40 and 4.00); the large triangles' in the soft lanes alone.
void list_soft_sample(bool soft, uvec4 c) {
    uvec4 ballot = subgroupBallot(soft);
    uint total = subgroupBallotBitCount(ballot);
    if (total == 0u) {
        return;
    }
    uint base = 0u;
    if (subgroupElect()) {
        base = atomicAdd(counters.candidates.x, total);
        uint room = uint(layer_candidates.length()), end = base + total;
        if (end > room || end < base) {
            leave_cores_to_the_triangles();
        }
        atomicMax(counters.candidate_groups.x, min((min(end, room) + 31u) / 32u, 65535u));
        atomicMax(counters.candidate_groups.y, 1u);
        atomicMax(counters.candidate_groups.z, 1u);
    }
    base = subgroupBroadcastFirst(base);
    uint at = base + subgroupBallotExclusiveBitCount(ballot);
    if (soft && at < uint(layer_candidates.length())) {
        layer_candidates[at] = c;
    }
}

// The candidate of sample k of `pixel` of the triangle `id`, its depth there `depth` (as the
// raster found it: what the candidates' build tests against the opaque sample).
uvec4 layer_candidate(uint k, ivec2 pixel, uint id, float depth) {
    return uvec4(uint(pixel.y) << 16 | uint(pixel.x), id, floatBitsToUint(depth), 1u << k);
}

#endif
