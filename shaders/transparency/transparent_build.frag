#version 450
#extension GL_GOOGLE_include_directive : require
// The transparent layers' build over a depth target (every technique but the compute raster).
#include "transparency/transparent_build.glsl"
