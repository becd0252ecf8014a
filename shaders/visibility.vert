#version 450
#extension GL_GOOGLE_include_directive : require
// The visibility raster: the culled meshlets, an indexed draw each (meshlet_cull.comp writes
// them); the draw's first instance is the meshlet instance. Positions are transformed as
// forward.vert transforms them, so depths equal the G-buffer pass's.
#include "common.glsl"

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 1) readonly buffer ObjectBuffer { ObjectData objects[]; };
// Per meshlet instance: (object, meshlet).
layout(std430, set = 0, binding = 2) readonly buffer MeshletInstanceBuffer { uvec2 meshlet_instances[]; };

layout(location = 0) in vec3 in_position;
layout(location = 0) flat out uint out_meshlet_instance;

void main() {
    uint id = gl_InstanceIndex;
    ObjectData o = objects[meshlet_instances[id].x];
    vec3 world = (o.model * vec4(in_position, 1.0)).xyz;
    out_meshlet_instance = id;
    gl_Position = frame.proj * frame.view * vec4(world, 1.0);
}
