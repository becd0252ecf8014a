// What the mesh techniques' raster passes write with anti-aliasing (docs/DESIGN.md#anti-aliasing):
// their attachments are multisampled, and each sample holds the display's linear light — the
// lit colour tone-mapped and clipped, before the gamma curve — so that the mean of a pixel's
// samples is a box filter in the light the display shows (an edge against a light far
// brighter than white stays smooth), and the tone map after them only gamma-encodes
// (tonemap.comp DISPLAY_LINEAR_INPUT). Without anti-aliasing they write what they always
// did. Needs shading_model.glsl.

#ifndef MANYLIGHTS_DISPLAY_OUTPUT_GLSL
#define MANYLIGHTS_DISPLAY_OUTPUT_GLSL

layout(constant_id = 41) const bool DISPLAY_LINEAR_OUTPUT = false;

// A lit linear colour under the pipeline's shading model.
vec4 target_lit(vec3 linear, float exposure) {
    return vec4(DISPLAY_LINEAR_OUTPUT ? display_linear(linear, exposure) : encode_output(linear, exposure), 1.0);
}

// A colour shown as it is (the surface debug views: gamma only).
vec4 target_shown(vec3 linear) {
    return vec4(DISPLAY_LINEAR_OUTPUT ? clamp(linear, 0.0, 1.0) : encode_gamma(linear), 1.0);
}

// A colour given as the 8-bit target stores it (the heat map and its legend).
vec4 target_stored(vec3 stored) {
    return vec4(DISPLAY_LINEAR_OUTPUT ? pow(clamp(stored, 0.0, 1.0), vec3(2.2)) : stored, 1.0);
}

#endif
