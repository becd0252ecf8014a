// The hardware visibility raster's surface tests. In scenes with masked or double-sided
// objects (SURFACE_TESTS) the pipeline draws both sides of every triangle and the fragment
// decides: a single-sided object's back face is dropped — by the rasteriser's own facing,
// so exactly the fragments back-face culling would drop — and so is a point an alpha mask
// cuts out (alpha_mask.glsl). Elsewhere nothing is tested and nothing discarded.
// Needs common.glsl.

#ifndef MANYLIGHTS_VISIBILITY_SURFACE_GLSL
#define MANYLIGHTS_VISIBILITY_SURFACE_GLSL

// (Declared by both variants: the build's reflection reads no #ifdef.)
#include "common/blended_cores.glsl"

#ifdef SURFACE_TESTS
layout(std430, set = 0, binding = 1) readonly buffer ObjectBuffer { ObjectData objects[]; };
#define ALPHA_MASK_BINDING 7
#include "common/alpha_mask.glsl"

layout(location = 0) flat in uint in_object;
layout(location = 1) in vec2 in_uv;

// Whether the side of the surface the viewer sees is drawn (a single-sided object's back face
// is not).
bool side_drawn() {
    return gl_FrontFacing || (objects[in_object].alpha_texture.x & OBJECT_DOUBLE_SIDED) != 0u;
}

// Whether the point at texture coordinates `uv` is there (its alpha mask keeps it).
bool point_there(vec2 uv) {
    uvec4 alpha_texture = objects[in_object].alpha_texture;
    return alpha_kept(raster_alpha(objects[in_object].alpha, alpha_texture.x), alpha_texture, uv);
}

bool surface_there() {
    return side_drawn() && point_there(in_uv);
}
#else
bool side_drawn() {
    return true;
}

bool surface_there() {
    return true;
}
#endif

#endif
