#version 450
#extension GL_GOOGLE_include_directive : require
// The transparent layers' build a thread per triangle, over the depth target.
#include "transparency/transparent_build_triangles.glsl"
