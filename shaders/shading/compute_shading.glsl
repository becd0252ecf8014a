// The end of both compute lighting passes (deferred_lighting.glsl from the G-buffer,
// visibility_lighting.glsl from the visibility buffer): a surface point shaded — or shown
// by a surface debug view — and stored into `out_image`: the colour target, or with
// LINEAR_OUTPUT (scenes with transparent layers) linear HDR with alpha 1 where a surface is
// and 0 for the background, which the transparent resolve blends the layers over and
// encodes. Needs lighting.glsl.

#ifndef MANYLIGHTS_COMPUTE_SHADING_GLSL
#define MANYLIGHTS_COMPUTE_SHADING_GLSL

#extension GL_KHR_shader_subgroup_arithmetic : require

// With COUNT_RAYS (`--light-stats` with rays): the shadow rays the frame traced from its opaque
// surfaces (x; the frame slot's, zeroed by the host before the frame), each subgroup adding
// its own. With anti-aliasing, y: the surfaces the visibility lighting shaded. Counting costs the 1k bench scene's lighting 3 % on the H100, so it is off unless
// asked for.
layout(constant_id = 23) const bool COUNT_RAYS = false;
layout(std430, set = 0, binding = 46) buffer RayCountBuffer { uvec4 ray_count; };

#ifdef LINEAR_OUTPUT
layout(set = 0, binding = 8, rgba16f) uniform writeonly image2D out_image;
#else
// Read too by the anti-aliased visibility lighting: a pixel whose surfaces' textures are bound
// by several dispatches gets each one's share added to what the one before stored.
layout(set = 0, binding = 8, rgba8) uniform image2D out_image;
#endif

// With COUNT_RAYS, the rays this invocation traced since the last count added to the frame's
// (a subgroup's at a time; every lane that shaded calls it).
void count_rays() {
    if (COUNT_RAYS) {
        uint traced = subgroupAdd(rays_traced);
        rays_traced = 0u;
        if (subgroupElect() && traced != 0u) {
            atomicAdd(ray_count.x, traced);
        }
    }
}

// `object_flags`: the object's OBJECT_* bits (the alpha debug view).
void shade_and_store(ivec2 p, vec2 frag_xy, vec3 world, vec3 n, PointMaterial m, uint object_flags) {
    vec3 color;
    if (debug_surface(world, n, m.albedo, m.roughness, m.metallic, object_flags, frag_xy, color)) {
        imageStore(out_image, p, vec4(encode_gamma(color), 1.0));
        return;
    }
    color = shade_point(world, n, m, frag_xy);
    count_rays();
    if (ray_cost_shown(color)) {
        imageStore(out_image, p, vec4(encode_gamma(color), 1.0));
        return;
    }
#ifdef LINEAR_OUTPUT
    imageStore(out_image, p, vec4(color, 1.0));
#else
    imageStore(out_image, p, vec4(encode_output(color, frame.exposure.x), 1.0));
#endif
}

// A surface point shaded, in linear light — or shown by a surface debug view (`debug`: its
// colour then, display-linear).
vec3 shade_linear(vec2 frag_xy, vec3 world, vec3 n, PointMaterial m, uint object_flags, out bool debug) {
    vec3 color;
    debug = debug_surface(world, n, m.albedo, m.roughness, m.metallic, object_flags, frag_xy, color);
    if (debug) {
        return clamp(color, 0.0, 1.0);
    }
    color = shade_point(world, n, m, frag_xy);
    count_rays();
    debug = ray_cost_shown(color);
    return debug ? clamp(color, 0.0, 1.0) : color;
}

// shade_linear's colour as the display's linear light (display_linear), for the anti-aliased
// resolve to weigh by the samples the surface covers.
vec3 display_of(vec3 shaded, bool debug) {
    return debug ? shaded : display_linear(shaded, frame.exposure.x);
}

// A surface point shaded (or a debug view's) as the display's linear light.
vec3 shade_display(vec2 frag_xy, vec3 world, vec3 n, PointMaterial m, uint object_flags) {
    bool debug;
    vec3 shaded = shade_linear(frag_xy, world, n, m, object_flags, debug);
    return display_of(shaded, debug);
}

// A pixel no opaque surface covers.
void store_background(ivec2 p) {
#ifdef LINEAR_OUTPUT
    imageStore(out_image, p, vec4(0.0));
#else
    imageStore(out_image, p, background_stored(p));
#endif
}

#endif
