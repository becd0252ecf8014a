// Alpha-masked shadow casters (ml-render depth_pass.rs MaskedPipeline): the graphics shadow
// passes — the sun's map and the point-light cubes — draw masked objects with a pipeline of
// their own whose fragment shader drops the points the mask cuts out (alpha_mask.glsl), so a
// leaf's shadow has the leaf's shape; every other object keeps the depth-only pipeline (no
// fragment test, early depth). The object's index comes by push constant: the passes' push
// blocks are already 128 bytes (the least a device guarantees), so this one carries the
// object's model matrix as its three rows (it is affine) and makes room for the index.
// Needs common.glsl. The vertex shader defines SHADOW_MASK_VERTEX first: it reads the texture
// coordinates and hands them on; the fragment shader reads the object buffer and the masks.

#ifndef MANYLIGHTS_SHADOW_MASK_GLSL
#define MANYLIGHTS_SHADOW_MASK_GLSL

// Keep in sync with depth_pass.rs ShadowMaskPush.
struct ShadowMaskPush {
    mat4 view_proj;       // sun: the light's view-projection; point lights: as OmniShadowPush's
    vec4 model_rows[3];   // the model matrix's rows (sun: model; point lights: model_to_light)
    uvec4 object;         // x: the object's index in the object buffer
};

layout(push_constant) uniform ShadowMaskPushBlock { ShadowMaskPush shadow_mask; };

#ifdef SHADOW_MASK_VERTEX
layout(location = 2) in vec2 in_uv; // the vertex buffer's texture coordinates (gpu_mesh.rs)
layout(location = 1) out vec2 out_uv;

// Object point `p` through the pushed model matrix; hands on its texture coordinates.
vec3 shadow_mask_model(vec3 p) {
    out_uv = in_uv;
    vec4 q = vec4(p, 1.0);
    return vec3(dot(shadow_mask.model_rows[0], q), dot(shadow_mask.model_rows[1], q), dot(shadow_mask.model_rows[2], q));
}
#else
layout(std430, set = 0, binding = 0) readonly buffer ObjectBuffer { ObjectData objects[]; };
#define ALPHA_MASK_BINDING 1
#include "common/alpha_mask.glsl"

layout(location = 1) in vec2 in_uv;

// Drops the fragment where the object's mask cuts it out.
void shadow_mask_test() {
    uint o = shadow_mask.object.x;
    // The texture transform per fragment: it is affine, so this equals transforming the
    // corners' coordinates before they are interpolated.
    if (!alpha_kept(objects[o].alpha, objects[o].alpha_texture, transform_uv(objects[o].uv_transform, in_uv))) {
        discard;
    }
}
#endif

#endif
