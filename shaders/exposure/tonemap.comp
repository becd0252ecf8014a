#version 450
#extension GL_GOOGLE_include_directive : require
// After the deferred render pass: HDR (RGBA16F, linear) → the 8-bit output, with the same
// encoding the forward path applies in its fragment shader (MODEL_PBR: tone-map first; not set
// for debug views, whose values are shown as they are). Alpha 0 marks pixels no object
// covers (the lighting subpass discards them): they get the background (background.glsl).
#include "common/common.glsl"
#include "common/shading_model.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform sampler2D hdr_image;
layout(set = 0, binding = 1, rgba8) uniform writeonly image2D out_image;
FRAME_BLOCK(2);
// Set 1: the scene's textures, of which the environment (the background).
#include "environment/environment.glsl"
#include "common/background.glsl"

// Anti-aliasing (shading/display_output.glsl): the image holds the mean of each pixel's
// samples in the display's linear light, premultiplied by the share of them that a surface
// covers (alpha); the rest shows the background. Only the gamma curve is left to apply.
layout(constant_id = 42) const bool DISPLAY_LINEAR_INPUT = false;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, textureSize(hdr_image, 0)))) {
        return;
    }
    vec4 hdr = texelFetch(hdr_image, p, 0);
    if (DISPLAY_LINEAR_INPUT) {
        imageStore(out_image, p, vec4(encode_over_background(hdr.rgb, 1.0 - hdr.a, background_linear(p)), 1.0));
        return;
    }
    imageStore(out_image, p, hdr.a == 0.0 ? background_stored(p) : vec4(encode_output(hdr.rgb, frame.exposure.x), 1.0));
}
