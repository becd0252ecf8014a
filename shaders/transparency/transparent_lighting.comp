#version 450
#extension GL_GOOGLE_include_directive : require
// The layers lit by every light (forward, deferred).
#include "transparency/transparent_lighting.glsl"
