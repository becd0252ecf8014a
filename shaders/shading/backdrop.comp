#version 450
#extension GL_GOOGLE_include_directive : require
// After the forward pass without anti-aliasing or transparent layers, where the background is
// the environment (--background environment): the pass cleared the colour target to alpha 0
// and wrote alpha 1 wherever a surface is; the pixels it left get the backdrop
// (common/background.glsl). With anti-aliasing or layers their resolve lays it instead.
#include "common/common.glsl"
#include "common/shading_model.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba8) uniform image2D out_image;
FRAME_BLOCK(1);
// Set 1: the scene's textures, of which the environment.
#include "environment/environment.glsl"
#include "common/background.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) {
        return;
    }
    if (imageLoad(out_image, p).a == 0.0) {
        imageStore(out_image, p, background_stored(p));
    }
}
