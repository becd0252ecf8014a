#version 450
#extension GL_GOOGLE_include_directive : require
// Technique `deferred`: the lighting subpass loops over every light.
#include "shading/deferred_frag.glsl"
