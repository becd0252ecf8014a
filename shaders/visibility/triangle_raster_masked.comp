#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_KHR_shader_subgroup_ballot : require
// The compute raster for scenes with masked objects (visibility/triangle_raster.glsl).
#define MASKED_SURFACES 1
#include "visibility/triangle_raster.glsl"
