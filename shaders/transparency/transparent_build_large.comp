#version 450
#extension GL_GOOGLE_include_directive : require
// The transparent layers' build of large triangles, a work group each, over the depth target.
#include "transparency/transparent_build_large.glsl"
