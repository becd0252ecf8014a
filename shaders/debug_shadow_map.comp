#version 450
#extension GL_GOOGLE_include_directive : require
// --debug-view shadow-map: the sun's shadow map over the whole output image (stretched), its
// depth in grey: white nearest the sun, black at the far plane (nothing there).
#include "common.glsl"
#include "textures.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba8) uniform writeonly image2D out_image;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_image);
    if (any(greaterThanEqual(p, size))) {
        return;
    }
    float depth = textureLod(shadow_depth, (vec2(p) + 0.5) / vec2(size), 0.0).r;
    // The sun's box spans depth 0 (nearest the sun) to 1 (the clear value: nothing there).
    float grey = 1.0 - depth;
    imageStore(out_image, p, vec4(vec3(grey), 1.0));
}
