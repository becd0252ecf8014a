#version 450
#extension GL_GOOGLE_include_directive : require
// The probe's compute half: 8×8 work groups (as deferred-compute's lighting), one pixel per
// invocation, into a storage image of the fragment half's format.
#include "probe/stage_probe.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 1, rgba8) uniform writeonly image2D out_image;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x < int(probe.size_lights.x) && p.y < int(probe.size_lights.y)) {
        imageStore(out_image, p, probe_pixel(p));
    }
}
