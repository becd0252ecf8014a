// The cores of transparent objects' constant, in a header of its own so that only the
// shaders that draw or leave out cores declare it (the visibility rasters, the layers'
// builds, instance_cull.comp): in common.glsl it would be every shader's. Needs common.glsl.

#ifndef MANYLIGHTS_BLENDED_CORES_GLSL
#define MANYLIGHTS_BLENDED_CORES_GLSL

// Whether the camera's visibility rasters draw the cores of transparent objects (layers on,
// the meshlet technique): an OBJECT_CORE object's points (or samples) of alpha 1 are drawn as
// opaque (alpha_mask.glsl raster_alpha) and the layers' builds leave them out
// (layer_triangles.glsl core_slack). A layer of alpha 1 shows its own colour and hides all
// behind it, so the picture is the one blending gives; most of a leaf's pixels move from the
// layers, whose cost follows fragments, to the opaque raster.
layout(constant_id = 25) const bool BLENDED_CORES = false;

// The ObjectData `alpha` the camera's visibility rasters test an object with (`flags`: its
// alpha_texture.x): a transparent object's core is its points of alpha 1, so with cores its
// cutoff is 1.
vec4 raster_alpha(vec4 alpha, uint flags) {
    if (BLENDED_CORES && (flags & OBJECT_CORE) != 0u) {
        alpha.x = 1.0;
    }
    return alpha;
}

#endif
