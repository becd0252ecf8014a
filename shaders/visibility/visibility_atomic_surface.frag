#version 450
#extension GL_GOOGLE_include_directive : require
// The hybrid raster's large triangles in scenes with masked or double-sided objects.
#define SURFACE_TESTS 1
#include "visibility/visibility_atomic_frag.glsl"
