#version 450
#extension GL_GOOGLE_include_directive : require
// Technique `clustered-cpu`: every fragment loops over its cluster's lights only.
#define CLUSTERED 1
#include "shading/forward_frag.glsl"
