#version 450
#extension GL_GOOGLE_include_directive : require
// Technique `forward`: brute force, every fragment loops over every light.
#include "shading/forward_frag.glsl"
