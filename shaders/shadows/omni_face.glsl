// The six faces of a point-light shadow cube as the shadow passes see them, the graphics
// ones (omni_shadow_vertex.glsl) and the compute raster (omni_raster.glsl) alike.

#ifndef MANYLIGHTS_OMNI_FACE_GLSL
#define MANYLIGHTS_OMNI_FACE_GLSL

// Forward and up of each face: +X, −X, +Y, −Y, +Z, −Z (Vulkan's cube layout, the classic face
// list: docs/DESIGN.md#point-light-shadows; ml_cpu::omni_shadow::face_axes).
const vec3 FACE_FORWARD[6] = vec3[](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1));
const vec3 FACE_UP[6] = vec3[](vec3(0, -1, 0), vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1), vec3(0, -1, 0), vec3(0, -1, 0));

// Clip position of `rel` (position − light, in radii) on cube face `face`: the face's rotation
// (look_at_rh's rows: side = forward × up, up' = side × forward, −forward), then `projection`.
vec4 omni_face_clip(mat4 projection, vec3 rel, int face) {
    vec3 f = FACE_FORWARD[face];
    vec3 s = normalize(cross(f, FACE_UP[face]));
    vec3 u = cross(s, f);
    return projection * vec4(dot(s, rel), dot(u, rel), -dot(f, rel), 1.0);
}

#endif
