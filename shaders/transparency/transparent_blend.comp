#version 450
#extension GL_GOOGLE_include_directive : require
// The transparent resolve's blend: the opaque pass left linear HDR (alpha 0 where no surface
// is) and transparent_lighting.comp lit the layers; per pixel they are blended over it back to
// front (layers.glsl) and the result encoded into the colour target, as tonemap.comp would
// have.
#include "common/common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

FRAME_BLOCK(0);
layout(set = 0, binding = 5) uniform sampler2D hdr_image;
layout(set = 0, binding = 8, rgba8) uniform writeonly image2D out_image;
#include "common/shading_model.glsl"
#include "clusters/cluster.glsl"
// Set 1: the scene's textures, of which the environment (the background).
#include "environment/environment.glsl"
#include "common/background.glsl"
#define LAYER_BINDING 20
#define LAYER_BLENDING 1
#include "transparency/layers.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) {
        return;
    }
    vec4 hdr = texelFetch(hdr_image, p, 0);
    imageStore(out_image, p, layered_output(p, hdr.rgb, hdr.a == 0.0, frame.exposure.x));
}
