// The coverage samples of the compute raster's 64-bit buffer (docs/DESIGN.md#anti-aliasing):
// VISIBILITY_SAMPLES per pixel (1: the pixel centre alone, anti-aliasing off), at Vulkan's
// standard sample positions, each keeping its own nearest depth << 32 | visibility id. A
// pixel's samples lie side by side in the buffer: the lighting reads them in one go.
// Included before raster_rules.glsl, it widens the rasters' pixel boxes to the samples.

#ifndef MANYLIGHTS_VISIBILITY_SAMPLES_GLSL
#define MANYLIGHTS_VISIBILITY_SAMPLES_GLSL

// Loops over a pixel's samples with small bodies are unrolled ([[unroll]]): their count is a
// constant once specialized, and an unrolled loop keeps its per-sample values (the samples
// read) in registers, where a loop indexes them from memory. Large bodies (the masked
// raster's alpha test) stay loops: unrolled, their registers cost more than the loop.
#extension GL_EXT_control_flow_attributes : require

// Samples per pixel: 1, 4, 8 or 16 (antialiasing.rs Antialiasing).
layout(constant_id = 24) const uint VISIBILITY_SAMPLES = 1u;

// Vulkan's standard sample positions (standardSampleLocations), in 1/16 pixel from the
// pixel's corner: a byte a sample (x in its low 4 bits, y in its high 4), four to a word, so
// that finding one is arithmetic — a constant array indexed in a loop that is not unrolled
// lives in memory.
const uvec4 SAMPLES_4 = uvec4(0xeaa26e26u, 0x00000000u, 0x00000000u, 0x00000000u);
const uvec4 SAMPLES_8 = uvec4(0x359db759u, 0x1ffb71d3u, 0x00000000u, 0x00000000u);
const uvec4 SAMPLES_16 = uvec4(0x7ca55799u, 0x3bbdda63u, 0xc22418e6u, 0x01fe4f80u);

// Sample s's position in sub-pixel units (1/256 pixel, raster_rules.glsl SUBPIXEL) from the
// pixel's corner.
ivec2 sample_offset(uint s) {
    if (VISIBILITY_SAMPLES == 1u) {
        return ivec2(128);
    }
    uvec4 table = SAMPLES_16;
    if (VISIBILITY_SAMPLES == 4u) {
        table = SAMPLES_4;
    }
    if (VISIBILITY_SAMPLES == 8u) {
        table = SAMPLES_8;
    }
    uint word = s < 4u ? table.x : s < 8u ? table.y : s < 12u ? table.z : table.w;
    uint position = (word >> (8u * (s & 3u))) & 0xffu;
    return ivec2(position & 15u, position >> 4u) * 16;
}


// The samples' extent in a pixel (sub-pixel units from its corner): a pixel may be covered
// only where a triangle's box reaches between them (raster_rules.glsl centres_in_box).
// Branches, not `?:` on the constant: the build's reflection evaluates no constant select.
ivec2 samples_lo() {
    if (VISIBILITY_SAMPLES == 16u) {
        return ivec2(0);
    }
    if (VISIBILITY_SAMPLES == 8u) {
        return ivec2(16);
    }
    if (VISIBILITY_SAMPLES == 4u) {
        return ivec2(32);
    }
    return ivec2(128);
}

ivec2 samples_hi() {
    if (VISIBILITY_SAMPLES == 4u) {
        return ivec2(224);
    }
    if (VISIBILITY_SAMPLES == 1u) {
        return ivec2(128);
    }
    return ivec2(240);
}
#define RASTER_SAMPLE_LO samples_lo()
#define RASTER_SAMPLE_HI samples_hi()

// Where sample s of `pixel` lies in the buffer, for an image `width` pixels wide.
uint sample_slot(ivec2 pixel, uint s, uint width) {
    return (uint(pixel.y) * width + uint(pixel.x)) * VISIBILITY_SAMPLES + s;
}

// Where a surface covering the samples `members` (a bit each) of `pixel` is shaded: the pixel
// centre where it covers every sample, else the mean of the samples it covers. Inside their
// hull either way (the standard positions surround the centre), so the point lies on the
// surface between its samples' points — which the light grid's marks rely on.
vec2 shading_xy(ivec2 pixel, uint members) {
    if (members == (1u << VISIBILITY_SAMPLES) - 1u) {
        return vec2(pixel) + 0.5;
    }
    ivec2 sum = ivec2(0);
    [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
        if ((members & (1u << k)) != 0u) {
            sum += sample_offset(k);
        }
    }
    return vec2(pixel) + vec2(sum) / (256.0 * float(bitCount(members)));
}

// Sample k's offset from the pixel centre, in pixels: how far a fragment shader, which sees
// its inputs at the centre, steps them (by their screen derivatives) to the sample.
vec2 sample_step(uint k) {
    return vec2(sample_offset(k)) / 256.0 - 0.5;
}

// Sample k's position in pixels in the image.
vec2 sample_xy(ivec2 pixel, uint k) {
    return vec2(pixel) + vec2(sample_offset(k)) / 256.0;
}

#endif
