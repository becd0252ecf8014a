// What forward.vert hands every mesh fragment shader (forward and clustered colour, the
// G-buffer pass), and the draw's push constants. Needs common.glsl (ObjectPush).

#ifndef MANYLIGHTS_MESH_FRAGMENT_INPUTS_GLSL
#define MANYLIGHTS_MESH_FRAGMENT_INPUTS_GLSL

layout(location = 0) in vec3 in_world_pos;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_tangent;
layout(push_constant) uniform PushBlock { ObjectPush object; };

#endif
