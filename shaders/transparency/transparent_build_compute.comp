#version 450
#extension GL_GOOGLE_include_directive : require
// The transparent layers' build in compute over the depth target.
#include "transparency/transparent_build_compute.glsl"
