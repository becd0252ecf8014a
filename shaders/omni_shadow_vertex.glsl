// What both point-light shadow vertex shaders share: the inputs and the object's transform.

layout(location = 0) in vec3 in_position;
layout(location = 0) out vec3 out_to_light;

layout(push_constant) uniform OmniShadowPushBlock { OmniShadowPush omni; };

vec3 omni_world_position() {
    return in_position * omni.position_scale.w + omni.position_scale.xyz;
}
