#version 450
#extension GL_GOOGLE_include_directive : require
// Technique `clustered-gpu`: every fragment loops over the light grid's lights near it.
#define LIGHT_GRID 1
#include "shading/forward_frag.glsl"
