#version 450
#extension GL_GOOGLE_include_directive : require
// The transparent resolve of forward and deferred: every light shades each layer.
#include "transparency/transparent_resolve.glsl"
