#version 450
#extension GL_GOOGLE_include_directive : require
// Technique `deferred` in scenes whose objects have textures of their own: the G-buffer has
// the roughness-metallic and emissive images too.
#define GBUFFER_MATERIAL 1
#include "shading/deferred_frag.glsl"
