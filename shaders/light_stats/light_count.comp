#version 450
#extension GL_GOOGLE_include_directive : require
// The light counts over the depth target.
#include "light_stats/light_count.glsl"
