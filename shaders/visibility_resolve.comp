#version 450
#extension GL_GOOGLE_include_directive : require
// The compute raster's 64-bit buffer made into the images the hardware raster leaves: the
// visibility id and the depth per pixel (id 0 and depth 1 where nothing was drawn, as the
// hardware pass clears them), which the depth pyramid and the lighting read unchanged.
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// Per pixel: x: the visibility id; y: the depth's bits (all ones: nothing drawn).
layout(std430, set = 0, binding = 0) readonly buffer VisibilityDepthBuffer { uvec2 visibility_depth[]; };
layout(set = 0, binding = 1, r32ui) uniform writeonly uimage2D visibility_out;
layout(set = 0, binding = 2, r32f) uniform writeonly image2D depth_out;
layout(push_constant) uniform ResolvePushBlock { uvec4 size; }; // xy: image size

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(p, size.xy))) {
        return;
    }
    uvec2 v = visibility_depth[p.y * size.x + p.x];
    bool empty = v.y == 0xffffffffu;
    imageStore(visibility_out, ivec2(p), uvec4(empty ? 0u : v.x));
    imageStore(depth_out, ivec2(p), vec4(empty ? 1.0 : uintBitsToFloat(v.y)));
}
