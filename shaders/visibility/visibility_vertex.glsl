// The visibility raster: the triangles the culling kept, one indexed draw per phase from the
// compacted index buffer (triangle_cull.comp writes it). An index is a draw slot and a vertex
// of that slot's meshlet; the vertex is pulled from the scene's vertex buffer and transformed
// as forward.vert transforms it, so depths equal the G-buffer pass's.
// With SURFACE_TESTS (visibility_surface.vert: scenes with masked or double-sided objects)
// it also hands the fragment its object and texture coordinates (visibility_surface.glsl).
#ifndef MANYLIGHTS_VISIBILITY_VERTEX_GLSL
#define MANYLIGHTS_VISIBILITY_VERTEX_GLSL

#include "common/common.glsl"

FRAME_BLOCK(0);
layout(std430, set = 0, binding = 1) readonly buffer ObjectBuffer { ObjectData objects[]; };
// Per draw slot: x: meshlet instance; y: object; z: its meshlet's first vertex; w: meshlet.
layout(std430, set = 0, binding = 2) readonly buffer DrawSlotBuffer { uvec4 draw_slots[]; };
layout(std430, set = 0, binding = 3) readonly buffer MeshletVertexBuffer { uint meshlet_vertices[]; };
layout(std430, set = 0, binding = 4) readonly buffer VertexBuffer { float vertex_data[]; };

#ifdef SURFACE_TESTS
layout(location = 0) flat out uint out_object;
layout(location = 1) out vec2 out_uv;
#endif

void main() {
    uint index = uint(gl_VertexIndex);
    uvec4 slot = draw_slots[index >> INDEX_VERTEX_BITS];
    uint b = VERTEX_FLOATS * meshlet_vertices[slot.z + (index & ((1u << INDEX_VERTEX_BITS) - 1u))];
    vec3 world = (objects[slot.y].model * vec4(vertex_data[b], vertex_data[b + 1u], vertex_data[b + 2u], 1.0)).xyz;
    gl_Position = frame.proj * frame.view * vec4(world, 1.0);
#ifdef SURFACE_TESTS
    out_object = slot.y;
    out_uv = transform_uv(objects[slot.y].uv_transform, vec2(vertex_data[b + 6u], vertex_data[b + 7u]));
#endif
}

#endif
