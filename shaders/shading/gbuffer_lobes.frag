#version 450
#extension GL_GOOGLE_include_directive : require
// The G-buffer pass where the PBR extensions vary per point: the textured images and three more.
#define GBUFFER_MATERIAL 1
#define GBUFFER_LOBES 1
#include "shading/gbuffer_frag.glsl"
