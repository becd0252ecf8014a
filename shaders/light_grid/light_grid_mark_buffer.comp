#version 450
#extension GL_GOOGLE_include_directive : require
// The light grid's marks from the compute raster's 64-bit buffer.
#define OPAQUE_DEPTH_BUFFER 1
#include "light_grid/light_grid_mark.glsl"
