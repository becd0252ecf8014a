#version 450
#extension GL_GOOGLE_include_directive : require
// One mip level of the environment's cube from the level above it: each texel the mean of
// the four it covers (what the prefilter's filtered lookups read).

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(set = 0, binding = 0, rgba16f) uniform readonly image2DArray finer_level;
layout(set = 0, binding = 1, rgba16f) uniform writeonly image2DArray coarser_level;

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(p.xy, imageSize(coarser_level).xy))) {
        return;
    }
    ivec3 q = ivec3(p.xy * 2, p.z);
    vec4 sum = imageLoad(finer_level, q) + imageLoad(finer_level, q + ivec3(1, 0, 0)) + imageLoad(finer_level, q + ivec3(0, 1, 0))
        + imageLoad(finer_level, q + ivec3(1, 1, 0));
    imageStore(coarser_level, p, sum * 0.25);
}
