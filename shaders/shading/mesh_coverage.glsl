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
// VISIBILITY_SAMPLES: the pass's samples per pixel (anti-aliasing).
#include "visibility/visibility_samples.glsl"

layout(constant_id = 16) const bool MASKED_DRAW = false;
layout(constant_id = 17) const bool DOUBLE_SIDED_DRAW = false;

// The point of its triangle a fragment is shaded at, and what the vertices give it there.
struct MeshPoint {
    vec3 world;
    vec3 normal;
    vec2 uv;
    vec4 tangent;
};

// Drops the fragment where the object is cut out — with several samples a pixel, the samples
// where it is: the alpha tested at each sample's own texture coordinates (smooth cut-out edges
// at the cost of one shading a pixel) — and returns the point it is shaded at: the pixel
// centre where it keeps every sample (always, without anti-aliasing), else the mean of the
// samples it keeps, as the visibility technique and the deferred lighting shade a surface
// that holds some of a pixel's samples; the inputs are stepped there from the centre by their
// screen derivatives. The normal is turned toward the viewer on a double-sided object's back
// face (glTF: its normals are reversed). The sample mask is written on every path: a shader
// that writes it anywhere leaves it undefined where it does not.
MeshPoint covered_point() {
    // Before any branch: derivatives need the whole quad.
    mat2x3 world_d = mat2x3(dFdx(in_world_pos), dFdy(in_world_pos));
    mat2x3 normal_d = mat2x3(dFdx(in_normal), dFdy(in_normal));
    mat2 uv_d = mat2(dFdx(in_uv), dFdy(in_uv));
    mat2x4 tangent_d = mat2x4(dFdx(in_tangent), dFdy(in_tangent));
    MeshPoint p = MeshPoint(in_world_pos, in_normal, in_uv, in_tangent);
    int kept = -1;
    if (MASKED_DRAW) {
        uint o = object.ids.x;
        if (VISIBILITY_SAMPLES == 1u) {
            if (!alpha_kept(objects[o].alpha, objects[o].alpha_texture, in_uv)) {
                discard;
            }
        } else {
            kept = 0;
            for (uint s = 0u; s < VISIBILITY_SAMPLES; s++) {
                vec2 uv = in_uv + uv_d * sample_step(s);
                if ((gl_SampleMaskIn[0] & (1 << s)) != 0 && alpha_kept(objects[o].alpha, objects[o].alpha_texture, uv)) {
                    kept |= 1 << s;
                }
            }
            if (kept == 0) {
                discard;
            }
        }
    }
    if (VISIBILITY_SAMPLES != 1u) {
        uint all_samples = (1u << VISIBILITY_SAMPLES) - 1u;
        uint held = uint(kept == -1 ? gl_SampleMaskIn[0] : kept) & all_samples;
        if (held != all_samples) {
            vec2 shift = shading_xy(ivec2(0), held) - 0.5;
            p.world += world_d * shift;
            p.normal += normal_d * shift;
            p.uv += uv_d * shift;
            p.tangent += tangent_d * shift;
        }
    }
    gl_SampleMask[0] = kept;
    if (DOUBLE_SIDED_DRAW && !gl_FrontFacing) {
        p.normal = -p.normal;
    }
    return p;
}

#endif
