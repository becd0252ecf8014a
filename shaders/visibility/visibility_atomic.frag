#version 450
#extension GL_GOOGLE_include_directive : require
#include "visibility/visibility_atomic_frag.glsl"
