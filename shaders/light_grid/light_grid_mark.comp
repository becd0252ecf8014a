#version 450
#extension GL_GOOGLE_include_directive : require
// The light grid's marks from the depth target.
#include "light_grid/light_grid_mark.glsl"
