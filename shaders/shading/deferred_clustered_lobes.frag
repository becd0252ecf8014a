#version 450
#extension GL_GOOGLE_include_directive : require
// Technique `deferred-clustered` where the PBR extensions vary per point.
#define CLUSTERED 1
#define GBUFFER_MATERIAL 1
#define GBUFFER_LOBES 1
#include "shading/deferred_frag.glsl"
