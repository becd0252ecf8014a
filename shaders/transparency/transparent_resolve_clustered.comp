#version 450
#extension GL_GOOGLE_include_directive : require
// The transparent resolve of the clustered forward techniques and deferred-clustered: each
// layer is shaded by its cluster's lights.
#define CLUSTERED 1
#include "transparency/transparent_resolve.glsl"
