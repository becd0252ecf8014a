#version 450
#extension GL_GOOGLE_include_directive : require
// Technique `deferred-clustered`: the lighting subpass loops over its cluster's lights only.
#define CLUSTERED 1
#include "shading/deferred_frag.glsl"
