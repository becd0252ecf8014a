// Point-light shadows (docs/DESIGN.md#point-light-shadows), read side: each shadowed light has
// a cube in the cube-map array `omni_shadows` holding, per texel, the distance from the light
// to the nearest surface over the light's radius. Compiled in only when OMNI_SHADOWS is set (a
// specialization constant), so renders without them run the loop they always ran.

#ifndef MANYLIGHTS_OMNI_SHADOW_GLSL
#define MANYLIGHTS_OMNI_SHADOW_GLSL

layout(constant_id = 12) const bool OMNI_SHADOWS = false;

// The surface point moves this many texels along its normal before the lookup (normal-offset
// bias: a lit surface at a grazing angle to the light stays clear of its own texels)…
const float OMNI_NORMAL_OFFSET_TEXELS = 1.5;
// …and compares this many texels nearer than it is (the depth spread within one texel).
const float OMNI_DEPTH_BIAS_TEXELS = 1.0;

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
        // World size of one texel at this distance (a face spans 90°: 2·dist across at most).
        float texel_world = dist * frame.omni_texel;
        vec3 d = to_point + n * (OMNI_NORMAL_OFFSET_TEXELS * texel_world);
        float reference = (length(d) - OMNI_DEPTH_BIAS_TEXELS * texel_world) / radius;
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

#endif
