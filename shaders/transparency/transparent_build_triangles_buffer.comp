#version 450
#extension GL_GOOGLE_include_directive : require
// The transparent layers' build a thread per triangle, over the compute raster's 64-bit buffer.
#define OPAQUE_DEPTH_BUFFER 1
#include "transparency/transparent_build_triangles.glsl"
