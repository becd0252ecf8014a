#version 450
#extension GL_GOOGLE_include_directive : require
// The transparent resolve's blend with anti-aliasing (the visibility technique): the lighting
// resolved every pixel into the colour target and left each opaque surface's linear colour
// at its first sample; a pixel with layers is blended again here, sample by sample
// (layers.glsl layered_samples_output). A pixel without keeps the lighting's colour.
#include "common/common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

FRAME_BLOCK(0);
layout(set = 0, binding = 8, rgba8) uniform writeonly image2D out_image;
#include "common/shading_model.glsl"
#include "clusters/cluster.glsl"
// Set 1: the scene's textures, of which the environment (the background).
#include "environment/environment.glsl"
#include "common/background.glsl"
#define OPAQUE_DEPTH_BUFFER 1
#include "common/opaque_depth.glsl"
#include "visibility/surface_colours.glsl"
#define LAYER_BINDING 20
#define LAYER_BLENDING 1
#define LAYER_SAMPLES 1
#include "transparency/layers.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y) || layer_heads[layer_pixel(p)] == LAYER_END) {
        return;
    }
    imageStore(out_image, p, layered_samples_output(p, frame.exposure.x));
}
