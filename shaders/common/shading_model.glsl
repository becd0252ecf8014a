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
// Whether some object's glTF PBR extensions vary over its surface: textures of theirs, or a
// clear coat over a normal map (the coat keeps the mesh's own normal). Without, each point
// has its object's lobes and the coat the surface's normal.
layout(constant_id = 47) const bool LOBE_TEXTURES = false;

// What an object's extension textures give at a point, each multiplying its factor (1: no
// texture; ml_cpu::material_lobes::LobeTexels), and the clear coat's normal (world, unit).
struct LobeTexels {
    vec2 coat;         // strength, roughness
    vec3 coat_normal;
    vec4 sheen;        // colour, roughness
    vec4 specular;     // colour, strength
    vec2 transmission; // transmission, the volume's thickness
};

// No texture, the coat on `n`.
LobeTexels no_lobe_texels(vec3 n) {
    return LobeTexels(vec2(1.0), n, vec4(1.0), vec4(1.0), vec2(1.0));
}

// The texels as the G-buffer's lobes image and a transparent layer's node keep them (needs
// common.glsl): the clear coat's octahedral normal snorm 2×16, (coat, coat roughness,
// transmission, thickness), sheen (colour, roughness) and specular (colour, strength) unorm
// 4×8 each.
uvec4 pack_lobe_texels(LobeTexels t) {
    return uvec4(packSnorm2x16(oct_encode(t.coat_normal)), packUnorm4x8(vec4(t.coat, t.transmission)), packUnorm4x8(t.sheen),
                 packUnorm4x8(t.specular));
}

LobeTexels unpack_lobe_texels(uvec4 w) {
    vec4 coat_transmission = unpackUnorm4x8(w.y);
    return LobeTexels(coat_transmission.xy, oct_decode(unpackSnorm2x16(w.x)), unpackUnorm4x8(w.z), unpackUnorm4x8(w.w), coat_transmission.zw);
}

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
