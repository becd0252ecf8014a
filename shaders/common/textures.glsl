// Set 1 of every shading path: the scene's textures (scene_textures.rs). The seed model
// binds them too but never samples them.

#ifndef MANYLIGHTS_TEXTURES_GLSL
#define MANYLIGHTS_TEXTURES_GLSL

layout(set = 1, binding = 0) uniform sampler2DShadow shadow_map; // the sun's depth, compared
layout(set = 1, binding = 1) uniform samplerCube sky;            // environment for reflections
layout(set = 1, binding = 2) uniform sampler2D albedo_map;
layout(set = 1, binding = 3) uniform sampler2D normal_map;       // tangent space, n·0.5 + 0.5
layout(set = 1, binding = 4) uniform sampler2D shadow_depth;     // the shadow map's depths (debug view)
// Point-light shadow cubes (omni_shadow.glsl): distance / radius, compared; and the same
// layers as plain depths, six per light (the shadow-cube debug view).
layout(set = 1, binding = 5) uniform samplerCubeArrayShadow omni_shadows;
layout(set = 1, binding = 6) uniform sampler2DArray omni_faces;
// The shadow atlas instead of the cubes (omni_shadow.glsl with SHADOW_ATLAS): distance /
// radius per texel in Z-order, and where each shadowed light's faces lie in it.
layout(std430, set = 1, binding = 7) readonly buffer ShadowAtlasBuffer { float atlas_depth[]; };
layout(std430, set = 1, binding = 8) readonly buffer ShadowAtlasTileBuffer { ShadowCubeTiles atlas_tiles[]; };

#endif
