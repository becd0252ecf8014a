// What the point-light shadow vertex shaders share: the inputs, the object's place relative
// to the light and, for the one-pass modes (multiview, layered), each face's rotation
// (omni_face.glsl).

layout(location = 0) in vec3 in_position;
layout(location = 0) out vec3 out_from_light; // in radii

layout(push_constant) uniform OmniShadowPushBlock { OmniShadowPush omni; };

vec3 omni_from_light() {
    return (omni.model_to_light * vec4(in_position, 1.0)).xyz;
}

#include "omni_face.glsl"
