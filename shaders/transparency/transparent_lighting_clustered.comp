#version 450
#extension GL_GOOGLE_include_directive : require
// The layers lit by their clusters' lights (the clustered techniques).
#define CLUSTERED 1
#include "transparency/transparent_lighting.glsl"
