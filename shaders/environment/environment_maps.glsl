// What the environment's prefiltering shares (environment_*.comp) with the lighting that reads
// its results (environment.glsl): the equirectangular mapping, the cube faces' directions, the
// spherical-harmonic basis and GGX's importance sampling. Mirrored by
// crates/ml-cpu/src/environment.rs (keep in sync; the image tests compare the two).

#ifndef MANYLIGHTS_ENVIRONMENT_MAPS_GLSL
#define MANYLIGHTS_ENVIRONMENT_MAPS_GLSL

const float ENV_PI = 3.14159265358979;

// Unit direction → equirectangular coordinates in [0, 1]²: u turns with the azimuth about +Y
// (u = 0.5 looks along −Z), v = 0 looks up.
vec2 equirect_uv(vec3 d) {
    return vec2(0.5 + atan(d.x, -d.z) / (2.0 * ENV_PI), acos(clamp(d.y, -1.0, 1.0)) / ENV_PI);
}

// The direction through texel centre `uv` ([0, 1]², v down) of cube face `face` (+X, −X, +Y,
// −Y, +Z, −Z: Vulkan's face selection inverted), not normalised.
vec3 cube_direction(int face, vec2 uv) {
    vec2 c = uv * 2.0 - 1.0;
    switch (face) {
    case 0: return vec3(1.0, -c.y, -c.x);
    case 1: return vec3(-1.0, -c.y, c.x);
    case 2: return vec3(c.x, 1.0, c.y);
    case 3: return vec3(c.x, -1.0, -c.y);
    case 4: return vec3(c.x, -c.y, 1.0);
    default: return vec3(-c.x, -c.y, -1.0);
    }
}

// The nine real spherical harmonics of bands 0–2 at unit direction d.
void sh9_basis(vec3 d, out float y[9]) {
    y[0] = 0.282095;
    y[1] = 0.488603 * d.y;
    y[2] = 0.488603 * d.z;
    y[3] = 0.488603 * d.x;
    y[4] = 1.092548 * d.x * d.y;
    y[5] = 1.092548 * d.y * d.z;
    y[6] = 0.315392 * (3.0 * d.z * d.z - 1.0);
    y[7] = 1.092548 * d.x * d.z;
    y[8] = 0.546274 * (d.x * d.x - d.y * d.y);
}

// The Hammersley point i of n.
vec2 hammersley(uint i, uint n) {
    return vec2(float(i) / float(n), float(bitfieldReverse(i)) * 2.3283064365386963e-10);
}

// A GGX half vector about +Z for `roughness` (α = roughness²) from the uniform point xi.
vec3 ggx_half_vector(vec2 xi, float roughness) {
    float a = roughness * roughness;
    float phi = 2.0 * ENV_PI * xi.x;
    float cos_theta = sqrt((1.0 - xi.y) / (1.0 + (a * a - 1.0) * xi.y));
    float sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    return vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

// `h` (about +Z) turned into the frame whose Z is the unit vector n.
vec3 about_normal(vec3 h, vec3 n) {
    vec3 up = abs(n.z) < 0.999 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
    vec3 t = normalize(cross(up, n));
    vec3 b = cross(n, t);
    return t * h.x + b * h.y + n * h.z;
}

#endif
