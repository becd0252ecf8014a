#version 450
#extension GL_GOOGLE_include_directive : require
// The G-buffer pass in scenes whose objects have textures of their own: two more images.
#define GBUFFER_MATERIAL 1
#include "shading/gbuffer_frag.glsl"
