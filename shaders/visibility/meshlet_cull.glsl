// What the culling passes share (instance_cull.comp, meshlet_cull.comp, triangle_cull.comp):
// their bindings and the tests. Every test is conservative — it removes only what no pixel of
// this frame could show — so culling never changes an image (docs/DESIGN.md#gpu-culling).
// Needs common.glsl.

#ifndef MANYLIGHTS_MESHLET_CULL_GLSL
#define MANYLIGHTS_MESHLET_CULL_GLSL


FRAME_BLOCK(0);
layout(std430, set = 0, binding = 1) readonly buffer InstanceBuffer { Instance instances[]; };
layout(std430, set = 0, binding = 2) readonly buffer ObjectBuffer { ObjectData objects[]; };
layout(std430, set = 0, binding = 3) readonly buffer MeshletBuffer { Meshlet meshlets[]; };
// The instances that passed the frustum test this frame (a work group each in meshlet_cull).
layout(std430, set = 0, binding = 4) buffer VisibleInstanceBuffer { uint visible_instances[]; };
layout(std430, set = 0, binding = 5) buffer CullCounterBuffer { CullCounters counters; };
// The meshlets to draw, a draw slot each (early from 0, late from the capacity on): x: the
// meshlet instance; y: its object; z: its first vertex in the meshlet vertex buffer; w: the
// meshlet. The triangle culling reads them, and so does the raster (a compacted index's
// high bits are the slot).
layout(std430, set = 0, binding = 6) buffer DrawSlotBuffer { uvec4 draw_slots[]; };
// Per meshlet instance: 1 where it was visible at the end of the last frame.
layout(std430, set = 0, binding = 7) buffer MeshletVisibilityBuffer { uint meshlet_visible[]; };
// Farthest depth over 2^(level+1) pixels a side (depth_pyramid.glsl); the late phase's test.
layout(std430, set = 0, binding = 8) readonly buffer DepthPyramidBuffer { float depth_pyramid[]; };
#include "visibility/depth_pyramid_test.glsl"
layout(std430, set = 0, binding = 9) readonly buffer MeshletVertexBuffer { uint meshlet_vertices[]; };
layout(std430, set = 0, binding = 10) readonly buffer MeshletTriangleBuffer { uint meshlet_triangles[]; };
layout(std430, set = 0, binding = 11) readonly buffer VertexBuffer { float vertex_data[]; };
// The triangles that survive, both phases one after the other: 3 compacted indices each
// (draw slot << INDEX_VERTEX_BITS | vertex in the meshlet) and their visibility ids.
layout(std430, set = 0, binding = 12) writeonly buffer CompactedIndexBuffer { uint compacted_indices[]; };
layout(std430, set = 0, binding = 13) writeonly buffer TriangleIdBuffer { uint triangle_ids[]; };
layout(push_constant) uniform CullPushBlock { CullPush cull; };

// Whether a world-space sphere is at least partly inside the view frustum (Vulkan clip
// space: −w ≤ x, y ≤ w, 0 ≤ z ≤ w; the planes are rows of the view-projection).
bool sphere_in_frustum(vec3 c, float r) {
    mat4 m = transpose(frame.proj * frame.view);
    vec4 planes[6] = vec4[6](m[3] + m[0], m[3] - m[0], m[3] + m[1], m[3] - m[1], m[2], m[3] - m[2]);
    for (int i = 0; i < 6; i++) {
        vec4 p = planes[i];
        if (dot(p.xyz, c) + p.w < -r * length(p.xyz)) {
            return false;
        }
    }
    return true;
}

// Whether every triangle of the meshlet faces away from the eye (its cone, placed by the
// instance's transform), so back-face culling would drop them all anyway. Only for
// transforms that keep angles (INSTANCE_CONE_CULLING); a mirror turns the cone around. A
// small margin keeps triangles seen nearly edge-on.
bool meshlet_backfacing(Meshlet m, mat4 model, uint flags) {
    float cutoff = m.cone_axis_cutoff.w;
    if ((flags & INSTANCE_CONE_CULLING) == 0u || cutoff >= 1.0) {
        return false;
    }
    vec3 axis = normalize(mat3(model) * m.cone_axis_cutoff.xyz);
    if ((flags & INSTANCE_MIRRORED) != 0u) {
        axis = -axis;
    }
    vec3 apex = (model * vec4(m.cone_apex.xyz, 1.0)).xyz;
    // Perspective: from the eye to the apex; orthographic: the view direction.
    vec3 forward = -vec3(frame.view[0][2], frame.view[1][2], frame.view[2][2]);
    vec3 to_apex = frame.camera_pos.w > 0.5 ? normalize(apex - frame.camera_pos.xyz) : forward;
    return dot(to_apex, axis) >= cutoff + 1e-3;
}

// Whether this frame's depth so far hides the whole sphere: its nearest depth lies behind the
// farthest depth over the pixels its projection covers (the depth pyramid at the level where
// those pixels are at most 2×2 texels). Spheres reaching the near plane are never hidden.
bool sphere_occluded(vec3 c, float r) {
    vec3 v = (frame.view * vec4(c, 1.0)).xyz;
    float near = frame.cluster_frustum.x;
    if (v.z + r > -near) {
        return false;
    }
    vec2 lo = vec2(1e30), hi = vec2(-1e30);
    for (int i = 0; i < 8; i++) {
        vec3 corner = v + r * vec3((i & 1) != 0 ? 1.0 : -1.0, (i & 2) != 0 ? 1.0 : -1.0, (i & 4) != 0 ? 1.0 : -1.0);
        vec4 clip = frame.proj * vec4(corner, 1.0);
        vec2 ndc = clip.xy / clip.w;
        lo = min(lo, ndc);
        hi = max(hi, ndc);
    }
    vec4 nearest = frame.proj * vec4(v.xy, v.z + r, 1.0);
    float depth = nearest.z / nearest.w;
    if (depth <= 0.0) {
        return false;
    }
    vec2 size = vec2(frame.viewport.xy);
    ivec2 p0 = clamp(ivec2(floor((lo * 0.5 + 0.5) * size)), ivec2(0), ivec2(size) - 1);
    ivec2 p1 = clamp(ivec2(floor((hi * 0.5 + 0.5) * size)), ivec2(0), ivec2(size) - 1);
    return depth > pyramid_farthest(frame.viewport.xy, int(opaque_uniform(cull.mode.z)), p0, p1);
}

#endif
