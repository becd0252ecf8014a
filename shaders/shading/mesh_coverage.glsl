// What a mesh fragment shader (forward, G-buffer) settles before it shades: whether the
// fragment is there at all (alpha masks) and which way its surface faces (double-sided
// objects). Each is a specialization constant of the pipeline (mesh_raster.rs
// SurfaceVariant), so the pipelines of opaque, single-sided objects — every object of the
// built-in scenes — keep neither test nor discard (and their early depth test).
// Needs common.glsl, scene_bindings.glsl and mesh_fragment_inputs.glsl.

#ifndef MANYLIGHTS_MESH_COVERAGE_GLSL
#define MANYLIGHTS_MESH_COVERAGE_GLSL

#define ALPHA_MASK_BINDING 11
#include "common/alpha_mask.glsl"

layout(constant_id = 16) const bool MASKED_DRAW = false;
layout(constant_id = 17) const bool DOUBLE_SIDED_DRAW = false;

// Drops the fragment where the object is cut out; returns the interpolated normal, turned
// toward the viewer on a double-sided object's back face (glTF: its normals are reversed).
vec3 covered_normal() {
    if (MASKED_DRAW) {
        uint o = object.ids.x;
        if (!alpha_kept(objects[o].alpha, objects[o].alpha_texture, in_uv)) {
            discard;
        }
    }
    return DOUBLE_SIDED_DRAW && !gl_FrontFacing ? -in_normal : in_normal;
}

#endif
