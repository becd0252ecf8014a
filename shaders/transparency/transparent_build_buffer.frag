#version 450
#extension GL_GOOGLE_include_directive : require
// The transparent layers' build over the compute raster's 64-bit visibility-depth buffer.
#define OPAQUE_DEPTH_BUFFER 1
#include "transparency/transparent_build.glsl"
