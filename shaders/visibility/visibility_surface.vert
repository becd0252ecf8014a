#version 450
#extension GL_GOOGLE_include_directive : require
// The visibility raster in scenes with masked or double-sided objects: the vertex shader also
// hands on the object and texture coordinates.
#define SURFACE_TESTS 1
#include "visibility/visibility_vertex.glsl"
