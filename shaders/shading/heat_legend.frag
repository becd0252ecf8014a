#version 450
#extension GL_GOOGLE_include_directive : require
// Legend of the cluster-heat debug view: the colour ramp (top part) over the number of lights
// per cluster it stands for, "0" at the left end and the top of the scale at the right
// (bottom part, a 3×5 pixel font scaled to fit).
#include "common/common.glsl"
#include "clusters/cluster.glsl"
#include "common/shading_model.glsl"
#include "shading/display_output.glsl"

layout(location = 0) in vec2 in_uv;
FRAME_BLOCK(0);
layout(location = 0) out vec4 out_color;

// 3×5 glyphs of 0-9, rows top to bottom, bit 14 = top left.
const uint DIGITS[10] = uint[10](0x7b6fu, 0x2c97u, 0x73e7u, 0x73cfu, 0x5bc9u, 0x79cfu, 0x79efu, 0x7249u, 0x7befu, 0x7bcfu);
const float RAMP_HEIGHT = 0.55;

bool glyph(uint digit, ivec2 cell) {
    if (cell.x < 0 || cell.x > 2 || cell.y < 0 || cell.y > 4) {
        return false;
    }
    return ((DIGITS[digit] >> uint(14 - (cell.y * 3 + cell.x))) & 1u) != 0u;
}

uint digit_count(uint value) {
    uint digits = 1u;
    for (uint v = value / 10u; v > 0u; v /= 10u) {
        digits++;
    }
    return digits;
}

// Whether pixel `p` (relative to the text's top-left corner) is ink of `value` written in
// glyphs of `scale` pixels per cell, one empty cell between digits.
bool number(uint value, ivec2 p, int scale) {
    if (p.x < 0 || p.y < 0) {
        return false;
    }
    ivec2 cell = p / scale;
    int column = cell.x / 4;
    int digits = int(digit_count(value));
    if (column >= digits) {
        return false;
    }
    uint d = value;
    for (int i = digits - 1; i > column; --i) {
        d /= 10u;
    }
    return glyph(d % 10u, ivec2(cell.x - column * 4, cell.y));
}

void main() {
    uint top = uint(frame.cluster_slices.z + 0.5);
    if (in_uv.y < RAMP_HEIGHT) {
        // The view's log scale: position t stands for 2^(t·log2(1 + top)) − 1 lights.
        out_color = target_stored(heat(in_uv.x));
        return;
    }
    // Pixel coordinates inside the text strip (the legend spans 0.33 × 0.08 of the image).
    vec2 size = vec2(frame.viewport.xy) * vec2(0.33, 0.08 * (1.0 - RAMP_HEIGHT));
    ivec2 px = ivec2(vec2(in_uv.x, (in_uv.y - RAMP_HEIGHT) / (1.0 - RAMP_HEIGHT)) * size);
    int scale = max(1, int(size.y) / 7);
    int top_width = (int(digit_count(top)) * 4 - 1) * scale;
    bool ink = number(0u, px - ivec2(scale), scale) || number(top, px - ivec2(int(size.x) - scale - top_width, scale), scale);
    out_color = target_stored(ink ? vec3(1.0) : vec3(0.0));
}
