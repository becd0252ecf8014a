// Point-light shadows (docs/DESIGN.md#point-light-shadows), read side: each shadowed light has
// a cube in the cube-map array `omni_shadows` holding, per texel, the distance from the light
// to the nearest surface over the light's radius — or, with SHADOW_RAYS, a shadow ray from the
// point to the light through the scene's triangles (shadow_rays.glsl). Compiled in only when
// OMNI_SHADOWS is set (a specialization constant), so renders without them run the loop they
// always ran.

#ifndef MANYLIGHTS_OMNI_SHADOW_GLSL
#define MANYLIGHTS_OMNI_SHADOW_GLSL

layout(constant_id = 12) const bool OMNI_SHADOWS = false;
// The lights' faces lie in the shadow atlas (docs/DESIGN.md#shadow-atlas), not in the cube
// array.
layout(constant_id = 15) const bool SHADOW_ATLAS = false;
// Shadowed lights are tested by a shadow ray each (no cubes).
layout(constant_id = 21) const bool SHADOW_RAYS = false;
// The point lights' shadows are maps (cubes or the atlas) and directional lights cast theirs
// by a shadow ray each: no map can hold a light 10 km away (lighting.glsl SUM_DIRECTIONAL).
layout(constant_id = 48) const bool DIRECTIONAL_RAYS = false;
// The shadow slot such a directional light carries (no cube or tile's).
const float DIRECTIONAL_RAY_SLOT = -1.0;

// Shadow rays read masked objects' alpha (the shading shaders that cut fragments themselves
// have included it with their binding already).
#ifndef ALPHA_MASK_BINDING
#define ALPHA_MASK_BINDING 45
#endif
#include "common/alpha_mask.glsl"
#define RAY_ALPHA_MASKS 1
#include "shadows/shadow_rays.glsl"

// A shadow ray's origin leaves the surface along its normal by this much per unit of the
// point's largest coordinate (at least 1 m): clear of its own triangle's rounding.
const float RAY_NORMAL_OFFSET = 1e-4;

// Where the shadow rays of the point `world` (normal `n`) start.
vec3 ray_origin(vec3 world, vec3 n) {
    vec3 a = abs(world);
    return world + n * (RAY_NORMAL_OFFSET * max(1.0, max(a.x, max(a.y, a.z))));
}

// The surface point moves this many texels along its normal before the lookup (normal-offset
// bias: a lit surface at a grazing angle to the light stays clear of its own texels)…
const float OMNI_NORMAL_OFFSET_TEXELS = 1.5;
// …and compares this many texels nearer than it is (the depth spread within one texel).
const float OMNI_DEPTH_BIAS_TEXELS = 1.0;

// The atlas's lookup of direction `d` (from the light, biased) against `reference`, the cube
// array's filter by hand: the same face and texel as cube sampling picks (Vulkan's cube-face
// table), and the four half-texel-apart bilinear comparisons summed — a 3×3 tent over the
// face's texels, clamped to the face (where the cube array would read the neighbouring face's
// texels).
float atlas_visibility(ShadowCubeTiles tiles, vec3 d, float reference) {
    float size = float(tiles.size);
    vec3 a = abs(d);
    uint face;
    float ma;
    vec2 sc_tc;
    if (a.x >= a.y && a.x >= a.z) {
        face = d.x >= 0.0 ? 0u : 1u;
        ma = a.x;
        sc_tc = vec2(d.x >= 0.0 ? -d.z : d.z, -d.y);
    } else if (a.y >= a.z) {
        face = d.y >= 0.0 ? 2u : 3u;
        ma = a.y;
        sc_tc = vec2(d.x, d.y >= 0.0 ? d.z : -d.z);
    } else {
        face = d.z >= 0.0 ? 4u : 5u;
        ma = a.z;
        sc_tc = vec2(d.z >= 0.0 ? d.x : -d.x, -d.y);
    }
    uint base = tiles.base[face];
    if (base == NO_TILE) {
        // No visible pixel samples this face (the plan keeps every face one may): lit.
        return 1.0;
    }
    // Texel coordinates (texel centres at i + 0.5); the taps at ±½ texel cover texels
    // i0 … i0 + 2 with weights (1 − f)/2, 1/2, f/2 along each axis.
    vec2 st = (sc_tc / ma + 1.0) * 0.5 * size;
    ivec2 i0 = ivec2(floor(st)) - 1;
    vec2 f = fract(st);
    vec3 wx = vec3(1.0 - f.x, 1.0, f.x) * 0.5, wy = vec3(1.0 - f.y, 1.0, f.y) * 0.5;
    int last = int(tiles.size) - 1;
    float lit = 0.0;
    for (int j = 0; j < 3; j++) {
        uint y = uint(clamp(i0.y + j, 0, last));
        float row = 0.0;
        for (int i = 0; i < 3; i++) {
            uint x = uint(clamp(i0.x + i, 0, last));
            row += reference <= atlas_depth[atlas_texel(base, uvec2(x, y))] ? wx[i] : 0.0;
        }
        lit += wy[j] * row;
    }
    return lit;
}

// Fraction of light `l` that reaches `world` (normal `n`): 1 for lights without a cube and
// points beyond the radius. 3×3-texel tent PCF: four bilinear comparisons half a texel
// apart along the face's axes (the cube array's sampler filters each one's four compares).
float omni_visibility(PointLight l, vec3 world, vec3 n) {
    // (Not `!OMNI_SHADOWS`: a spec-constant operation that SPIR-V reflection cannot evaluate.)
    if (OMNI_SHADOWS && l.color.w != 0.0) {
        vec3 to_point = world - l.position_radius.xyz;
        float radius = l.position_radius.w;
        float dist = length(to_point);
        if (dist >= radius) {
            return 1.0;
        }
        // Every shadowed light by a ray, or (under maps) the directional ones.
        bool by_ray = SHADOW_RAYS;
        if (DIRECTIONAL_RAYS) {
            by_ray = l.color.w == DIRECTIONAL_RAY_SLOT;
        }
        if (by_ray) {
            return ray_occluded(ray_origin(world, n), l.position_radius.xyz) ? 0.0 : 1.0;
        }
        // One texel of a face in face units: the cube array's, or in the atlas the light's own.
        uint slot = uint(l.color.w) - 1u;
        float texel = frame.omni_texel;
        if (SHADOW_ATLAS) {
            texel = 2.0 / float(atlas_tiles[slot].size);
        }
        // World size of one texel at this distance (a face spans 90°: 2·dist across at most).
        float texel_world = dist * texel;
        vec3 d = to_point + n * (OMNI_NORMAL_OFFSET_TEXELS * texel_world);
        float reference = (length(d) - OMNI_DEPTH_BIAS_TEXELS * texel_world) / radius;
        if (SHADOW_ATLAS) {
            return atlas_visibility(atlas_tiles[slot], d, reference);
        }
        vec3 a = abs(d);
        // The face's texel axes (Vulkan's cube-face table): x-faces run along z and y, y-faces
        // along x and z, z-faces along x and y. Half a texel in direction units is ma·texel/2.
        bool major_x = a.x >= a.y && a.x >= a.z;
        bool major_y = !major_x && a.y >= a.z;
        vec3 u = major_x ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
        vec3 v = major_y ? vec3(0.0, 0.0, 1.0) : vec3(0.0, 1.0, 0.0);
        float half_texel = 0.5 * max(a.x, max(a.y, a.z)) * frame.omni_texel;
        u *= half_texel;
        v *= half_texel;
        float cube = l.color.w - 1.0;
        float lit = texture(omni_shadows, vec4(d - u - v, cube), reference) + texture(omni_shadows, vec4(d + u - v, cube), reference)
            + texture(omni_shadows, vec4(d - u + v, cube), reference) + texture(omni_shadows, vec4(d + u + v, cube), reference);
        return 0.25 * lit;
    }
    return 1.0;
}

// A light's contribution `c` at `world` with its shadow: times omni_visibility where the
// light casts one. Only where `c` is not zero — every model gives exactly zero beyond the
// radius and where the light is behind the surface (N·L ≤ 0) — so that no shadow ray is
// traced (nor cube read) for light that would be multiplied by zero anyway.
vec3 shadowed(vec3 c, PointLight l, vec3 world, vec3 n) {
    if (OMNI_SHADOWS && l.color.w != 0.0 && c != vec3(0.0)) {
        return c * omni_visibility(l, world, n);
    }
    return c;
}

#endif
