#version 450
#extension GL_GOOGLE_include_directive : require
// G-buffer of deferred-compute: 12 bytes per pixel besides depth — the normal (octahedral, two
// floats: exact enough that the seed's sharp highlights do not move) and the object's index
// (its material comes from the object buffer at full precision). Position comes from depth.
#include "common.glsl"

layout(location = 0) in vec3 in_world_pos;
layout(location = 1) in vec3 in_normal;
layout(push_constant) uniform PushBlock { ObjectPush object; };

layout(location = 0) out vec2 out_normal;
layout(location = 1) out uint out_object;

void main() {
    out_normal = oct_encode(normalize(in_normal));
    out_object = object.ids.x;
}
