#version 450
#extension GL_GOOGLE_include_directive : require
// Technique `deferred` with anti-aliasing, in scenes whose objects have textures of their own.
#define GBUFFER_MATERIAL 1
#define MULTISAMPLED 1
#include "shading/deferred_frag.glsl"
