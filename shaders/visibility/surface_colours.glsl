// The opaque surfaces' linear colours, for the transparent layers' anti-aliased blend
// (layers.glsl LAYER_SAMPLES): the visibility lighting stores each surface's colour at its
// pixel's first sample holding it (its leader), in the compute raster's sample layout
// (visibility_samples.glsl sample_slot), as two half floats a pair; the blend reads them.
// Needs common.glsl and visibility_samples.glsl.

#ifndef MANYLIGHTS_SURFACE_COLOURS_GLSL
#define MANYLIGHTS_SURFACE_COLOURS_GLSL

layout(std430, set = 0, binding = 47) buffer SurfaceColourBuffer { uvec2 surface_colours[]; };

// Half floats end at 65504: brighter is kept as that (the tone map has long saturated).
void store_surface_colour(ivec2 p, uint leader, vec3 linear) {
    vec3 c = min(linear, vec3(65504.0));
    surface_colours[sample_slot(p, leader, frame.viewport.x)] = uvec2(packHalf2x16(c.rg), packHalf2x16(vec2(c.b, 0.0)));
}

vec3 surface_colour(ivec2 p, uint leader) {
    uvec2 c = surface_colours[sample_slot(p, leader, frame.viewport.x)];
    return vec3(unpackHalf2x16(c.x), unpackHalf2x16(c.y).x);
}

#endif
