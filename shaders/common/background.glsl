// The backdrop where no surface is (docs/usage.md --background): the fixed colour CLEAR_COLOR
// or, under BACKGROUND_ENVIRONMENT, the environment seen along the pixel's ray — exposed and
// tone-mapped as a surface's light is, sampled from the radiance cube at the level whose
// texels are about a pixel wide. Debug views keep the colour. Needs `frame`, shading_model.glsl
// (aces_tone_map) and environment.glsl.

#ifndef MANYLIGHTS_BACKGROUND_GLSL
#define MANYLIGHTS_BACKGROUND_GLSL

#include "common/world_from_depth.glsl"

layout(constant_id = 46) const bool BACKGROUND_ENVIRONMENT = false;

// The environment's radiance along pixel p's ray (an orthographic camera's rays are parallel:
// one direction everywhere).
vec3 environment_seen(ivec2 p) {
    vec2 xy = vec2(p) + 0.5;
    vec3 d = normalize(world_from_depth(xy, 1.0) - world_from_depth(xy, 0.0));
    mat3 to_image = environment_to_image();
    // A pixel spans about 2 / (proj[1][1]·height) rad at the centre, a cube texel (π/2) / face.
    float face = float(textureSize(environment_radiance, 0).x);
    float pixel = 2.0 / (frame.proj[1][1] * float(frame.viewport.y));
    float level = log2(max(pixel * face / (0.5 * 3.14159265), 1.0));
    return textureLod(environment_radiance, to_image * d, level).rgb * environment.params.x;
}

// Whether pixel p shows the environment behind the surfaces.
bool shows_environment() {
    if (BACKGROUND_ENVIRONMENT) {
        return frame.viewport.z == DEBUG_VIEW_NONE;
    }
    return false;
}

// The backdrop in the display's linear light (before the gamma curve). An environment is pbr's
// (the settings refuse it elsewhere): its curve always, whatever the includer's MODEL_PBR
// says (the tone map's is off where it only gamma-encodes).
vec3 background_linear(ivec2 p) {
    if (shows_environment()) {
        return clamp(aces_tone_map(environment_seen(p) * frame.exposure.x), 0.0, 1.0);
    }
    return pow(CLEAR_COLOR.rgb, vec3(2.2));
}

// The backdrop as the 8-bit target stores it.
vec4 background_stored(ivec2 p) {
    if (shows_environment()) {
        return vec4(encode_gamma(background_linear(p)), 1.0);
    }
    return CLEAR_COLOR;
}

#endif
