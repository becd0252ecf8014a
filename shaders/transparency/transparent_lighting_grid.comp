#version 450
#extension GL_GOOGLE_include_directive : require
// The layers lit by the light grid's lights (the techniques whose lights the GPU assigns).
#define LIGHT_GRID 1
#include "transparency/transparent_lighting.glsl"
