// The surface tests of the compute rasters (triangle_raster.comp, triangle_raster_large.comp,
// omni_raster.glsl): a double-sided object's triangles are drawn whichever way they face, and
// a masked object's pixel (or sample) is drawn only where its alpha mask keeps the point the
// pixel centre (or sample) sees (alpha_mask.glsl). That point comes from the triangle's clip-space corners, not from the
// snapped edge functions, so a triangle clipped into a polygon, or crossing the eye's plane,
// finds the same point. Opaque triangles skip all of it.
// Needs common.glsl and alpha_mask.glsl.

#ifndef MANYLIGHTS_RASTER_SURFACE_GLSL
#define MANYLIGHTS_RASTER_SURFACE_GLSL

// Whether the scene has masked or double-sided objects at all (meshlets.rs
// surface_constants): without, every surface test compiles away and the rasters are the
// opaque ones, register for register.
layout(constant_id = 18) const bool SURFACE_TESTS = true;
// Whether it has masked objects (meshlets.rs, the second of surface_constants): without, the
// alpha tests compile away while double-sided objects keep their tests. (Shared memory does
// not: a masked path that holds any is a shader module of its own, triangle_raster.glsl.)
layout(constant_id = 19) const bool MASK_TESTS = true;

// A masked triangle's test (masked false: every pixel is kept).
struct SurfaceTest {
    bool masked;
    vec4 alpha;          // its object's ObjectData.alpha
    uvec4 alpha_texture; // and alpha_texture
    vec4 clip[3];        // its clip-space corners
    vec2 uv[3];          // their texture coordinates
};

// Perspective-correct barycentrics of the point of the triangle with clip-space corners a, b,
// c that projects to `ndc`: the weights λ with Σλ = 1 whose Σλ·corner lies on the pixel's
// line of sight (x − ndc.x·w = 0 and y − ndc.y·w = 0), i.e. orthogonal to both rows below.
// Homogeneous, so it holds for corners behind the eye too.
vec3 clip_barycentrics(vec4 a, vec4 b, vec4 c, vec2 ndc) {
    vec3 w = vec3(a.w, b.w, c.w);
    vec3 l = cross(vec3(a.x, b.x, c.x) - ndc.x * w, vec3(a.y, b.y, c.y) - ndc.y * w);
    return l / (l.x + l.y + l.z);
}

// Whether the point `xy` (in pixels, of an image of `size` pixels) is drawn.
bool surface_kept_at(SurfaceTest s, vec2 xy, vec2 size) {
    // (Not `!MASK_TESTS || …`: the reflection cannot evaluate a negated constant.)
    if (MASK_TESTS && s.masked) {
        vec2 ndc = xy / size * 2.0 - 1.0;
        vec3 l = clip_barycentrics(s.clip[0], s.clip[1], s.clip[2], ndc);
        return alpha_kept(s.alpha, s.alpha_texture, l.x * s.uv[0] + l.y * s.uv[1] + l.z * s.uv[2]);
    }
    return true;
}

// Whether the centre of `pixel` (in an image of `size` pixels) is drawn.
bool surface_kept(SurfaceTest s, ivec2 pixel, vec2 size) {
    return surface_kept_at(s, vec2(pixel) + 0.5, size);
}

// The test of a masked object's triangle: the object's ObjectData `alpha` and
// `alpha_texture`, the triangle's clip-space corners a, b, c and their texture coordinates.
SurfaceTest masked_surface(vec4 alpha, uvec4 alpha_texture, vec4 a, vec4 b, vec4 c, vec2 ua, vec2 ub, vec2 uc) {
    SurfaceTest s;
    s.masked = true;
    s.alpha = alpha;
    s.alpha_texture = alpha_texture;
    s.clip[0] = a;
    s.clip[1] = b;
    s.clip[2] = c;
    s.uv[0] = ua;
    s.uv[1] = ub;
    s.uv[2] = uc;
    return s;
}

// No test: every pixel kept.
SurfaceTest no_surface_test() {
    SurfaceTest s;
    s.masked = false;
    return s;
}

#endif
