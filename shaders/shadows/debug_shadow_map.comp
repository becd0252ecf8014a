#version 450
#extension GL_GOOGLE_include_directive : require
// The shadow-map debug views, painted over the whole output image, depth in grey (white
// nearest the light, black where nothing is: the clear value).
// --debug-view shadow-map: the sun's shadow map, stretched.
// --debug-view shadow-cube (CUBE): the six faces of the first shadowed point light's cube,
// unfolded as a cross (+Y above; −X, +Z, +X, −Z across; −Y below), each face as its texels
// lie (u right, v down), which makes the cross's shared edges meet.
// --debug-view shadow-atlas (ATLAS): the shadow atlas, ATLAS_BLOCKS blocks of ATLAS_SIDE²
// texels, ATLAS_COLUMNS × ATLAS_ROWS of them, scaled to fit (each pixel shows the texel at its corner);
// beyond the last block, black.
#include "common/common.glsl"
#include "common/textures.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(constant_id = 0) const bool CUBE = false;
layout(constant_id = 1) const bool ATLAS = false;
layout(constant_id = 2) const uint ATLAS_BLOCKS = 1u;
layout(constant_id = 3) const uint ATLAS_SIDE = 1u;
layout(constant_id = 4) const uint ATLAS_COLUMNS = 1u;
layout(constant_id = 5) const uint ATLAS_ROWS = 1u;

layout(set = 0, binding = 0, rgba8) uniform writeonly image2D out_image;

// Cross cell (column, row) of each face +X, −X, +Y, −Y, +Z, −Z.
const ivec2 FACE_CELL[6] = ivec2[](ivec2(2, 1), ivec2(0, 1), ivec2(1, 0), ivec2(1, 2), ivec2(1, 1), ivec2(3, 1));

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_image);
    if (any(greaterThanEqual(p, size))) {
        return;
    }
    float depth = 1.0;
    if (ATLAS) {
        // (Spec constants copied at run time: SPIR-V reflection cannot evaluate operations on them.)
        uint side = ATLAS_SIDE, columns = ATLAS_COLUMNS, rows = ATLAS_ROWS;
        uvec2 extent = uvec2(columns, rows) * side;
        // One scale for both axes: the atlas keeps its shape.
        float scale = max(float(extent.x) / float(size.x), float(extent.y) / float(size.y));
        uvec2 texel = uvec2(vec2(p) * scale);
        uvec2 block = texel / side;
        uint b = block.y * columns + block.x;
        if (all(lessThan(texel, extent)) && b < ATLAS_BLOCKS) {
            depth = atlas_depth[atlas_texel(b * side * side, texel % side)];
        }
    } else if (CUBE) {
        // Square cells, as large as fit 4 × 3 of them; outside the cross stays black.
        int cell = max(min(size.x / 4, size.y / 3), 1);
        ivec2 c = p / cell;
        int faces = textureSize(omni_faces, 0).x;
        for (int face = 0; face < 6; ++face) {
            if (c == FACE_CELL[face]) {
                ivec2 texel = (p - c * cell) * faces / cell;
                depth = texelFetch(omni_faces, ivec3(texel, face), 0).r;
            }
        }
    } else {
        depth = textureLod(shadow_depth, (vec2(p) + 0.5) / vec2(size), 0.0).r;
    }
    imageStore(out_image, p, vec4(vec3(1.0 - depth), 1.0));
}
