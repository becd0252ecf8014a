// Which shading model a pipeline is built for: specialization constants (set from --shading
// by name, settings.rs Shading, for every pass that shades or tone-maps), so each pipeline
// carries only its model's code.
// A uniform switch cost the seed model's fragment shaders 1.3–1.4× on the H100 (measured):
// the other models' code still took registers.

#ifndef MANYLIGHTS_SHADING_MODEL_GLSL
#define MANYLIGHTS_SHADING_MODEL_GLSL

layout(constant_id = 10) const bool MODEL_BLINN_PHONG = false;
// pbr; in the tone-map pass: "apply pbr's tone map" (not for debug views).
layout(constant_id = 11) const bool MODEL_PBR = false;
// Whether the scene's objects have textures of their own (glTF; surface.glsl): with the
// runtime test alone the seed scene's G-buffer pass took 1.90 ms instead of 1.55 and its
// forward pass at 64 lights 11.1 ms instead of 10.2 on the H100 (measured). Without them the
// G-buffer's material and emissive attachments are neither written nor read.
layout(constant_id = 13) const bool OBJECT_TEXTURES = false;
// Highlights widened by the spread of the normals a filtered normal map averages
// (surface.glsl normal_spread; --specular-aa).
layout(constant_id = 43) const bool SPECULAR_AA = true;

// ACES filmic curve (Narkowicz 2015's fit): HDR → [0, 1].
vec3 aces_tone_map(vec3 x) {
    return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

// Linear colour → what the 8-bit target stores under the pipeline's model: scaled by the
// exposure (FrameUniforms::exposure.x, 2^EV; 1 leaves every value as it was), then pbr
// tone-maps its HDR result, the seed models clip; then gamma 1/2.2.
vec3 encode_output(vec3 linear, float exposure) {
    linear *= exposure;
    if (MODEL_PBR) {
        linear = aces_tone_map(linear);
    }
    return encode_gamma(linear);
}

// What encode_output shows before its gamma curve, clipped to what the target holds: the
// display's linear light, in which anti-aliasing averages a pixel's surfaces (so that an edge
// against a light far brighter than white stays smooth once clipped or tone-mapped).
vec3 display_linear(vec3 linear, float exposure) {
    linear *= exposure;
    if (MODEL_PBR) {
        linear = aces_tone_map(linear);
    }
    return clamp(linear, 0.0, 1.0);
}

#endif
