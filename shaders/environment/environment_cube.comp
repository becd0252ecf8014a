#version 450
#extension GL_GOOGLE_include_directive : require
// The environment's equirectangular image resampled into level 0 of its cube (one thread a
// texel of a face): bilinear between the four nearest texels, wrapping round in azimuth —
// the CPU reference's `EnvironmentImage::radiance`.
#include "environment/environment_maps.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(set = 0, binding = 0) uniform sampler2D equirect;
layout(set = 0, binding = 1, rgba16f) uniform writeonly image2DArray cube_level;

vec3 texel(ivec2 p, ivec2 size) {
    p.x = (p.x % size.x + size.x) % size.x;
    p.y = clamp(p.y, 0, size.y - 1);
    return texelFetch(equirect, p, 0).rgb;
}

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    ivec2 face_size = imageSize(cube_level).xy;
    if (any(greaterThanEqual(p.xy, face_size))) {
        return;
    }
    vec3 d = normalize(cube_direction(p.z, (vec2(p.xy) + 0.5) / vec2(face_size)));
    ivec2 size = textureSize(equirect, 0);
    vec2 f = equirect_uv(d) * vec2(size) - 0.5;
    vec2 f0 = floor(f);
    vec2 t = f - f0;
    ivec2 i = ivec2(f0);
    vec3 top = mix(texel(i, size), texel(i + ivec2(1, 0), size), t.x);
    vec3 bottom = mix(texel(i + ivec2(0, 1), size), texel(i + ivec2(1, 1), size), t.x);
    imageStore(cube_level, p, vec4(mix(top, bottom, t.y), 1.0));
}
