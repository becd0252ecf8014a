#version 450
#extension GL_GOOGLE_include_directive : require
// Technique `deferred-clustered` with anti-aliasing, where the PBR extensions vary per point.
#define CLUSTERED 1
#define GBUFFER_MATERIAL 1
#define GBUFFER_LOBES 1
#define MULTISAMPLED 1
#include "shading/deferred_frag.glsl"
