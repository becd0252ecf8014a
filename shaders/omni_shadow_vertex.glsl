// What the point-light shadow vertex shaders share: the inputs, the object's place relative
// to the light and, for the one-pass modes (multiview, layered), each face's rotation.

layout(location = 0) in vec3 in_position;
layout(location = 0) out vec3 out_from_light; // in radii

layout(push_constant) uniform OmniShadowPushBlock { OmniShadowPush omni; };

vec3 omni_from_light() {
    return (omni.model_to_light * vec4(in_position, 1.0)).xyz;
}

// Forward and up of each face: +X, −X, +Y, −Y, +Z, −Z (Vulkan's cube layout, the classic face
// list: docs/DESIGN.md#point-light-shadows; ml_cpu::omni_shadow::face_axes).
const vec3 FACE_FORWARD[6] = vec3[](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1));
const vec3 FACE_UP[6] = vec3[](vec3(0, -1, 0), vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1), vec3(0, -1, 0), vec3(0, -1, 0));

// Clip position of `rel` (position − light, in radii) on cube face `face`: the face's rotation
// (look_at_rh's rows: side = forward × up, up' = side × forward, −forward), then the push
// constant's projection.
vec4 omni_face_clip(vec3 rel, int face) {
    vec3 f = FACE_FORWARD[face];
    vec3 s = normalize(cross(f, FACE_UP[face]));
    vec3 u = cross(s, f);
    return omni.view_proj * vec4(dot(s, rel), dot(u, rel), -dot(f, rel), 1.0);
}
