#version 450
#extension GL_GOOGLE_include_directive : require
// Technique `deferred` with anti-aliasing: the lighting subpass reads the samples.
#define MULTISAMPLED 1
#include "shading/deferred_frag.glsl"
