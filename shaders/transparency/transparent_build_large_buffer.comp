#version 450
#extension GL_GOOGLE_include_directive : require
// The transparent layers' build of large triangles, a work group each, over the compute raster's 64-bit buffer.
#define OPAQUE_DEPTH_BUFFER 1
#include "transparency/transparent_build_large.glsl"
