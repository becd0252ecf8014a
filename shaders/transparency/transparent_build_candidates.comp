#version 450
#extension GL_GOOGLE_include_directive : require
// The transparent layers' build from the compute raster's candidates (cores of transparent
// objects), over its 64-bit buffer.
#define OPAQUE_DEPTH_BUFFER 1
#define LAYER_CANDIDATE_BUILD 1
#include "transparency/transparent_build_candidates.glsl"
