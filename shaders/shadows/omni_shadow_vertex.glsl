// The point-light shadow vertex shaders, one body for every mode: the object's place relative
// to the light (in radii) and its clip position — copy and direct: through the face's
// view-projection; OMNI_MULTIVIEW (view i is face i) and OMNI_LAYERED (instance i draws face i
// into layer i): the face's rotation (omni_face.glsl), then the projection. The wrappers
// (omni_shadow*.vert) define the mode, and OMNI_SHADOW_MASKED for alpha-masked objects' pipeline
// (shadow_mask.glsl: the object's matrix and index by its push constants, the texture
// coordinates handed on).

#include "common/common.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 0) out vec3 out_from_light; // in radii

#ifdef OMNI_SHADOW_MASKED
#define SHADOW_MASK_VERTEX
#include "shadows/shadow_mask.glsl"

#define OMNI_VIEW_PROJ shadow_mask.view_proj

vec3 omni_from_light() {
    return shadow_mask_model(in_position);
}
#else
layout(push_constant) uniform OmniShadowPushBlock { OmniShadowPush omni; };

#define OMNI_VIEW_PROJ omni.view_proj

vec3 omni_from_light() {
    return (omni.model_to_light * vec4(in_position, 1.0)).xyz;
}
#endif

#include "shadows/omni_face.glsl"

void main() {
    out_from_light = omni_from_light();
#if defined(OMNI_LAYERED)
    gl_Layer = gl_InstanceIndex;
    gl_Position = omni_face_clip(OMNI_VIEW_PROJ, out_from_light, gl_InstanceIndex);
#elif defined(OMNI_MULTIVIEW)
    gl_Position = omni_face_clip(OMNI_VIEW_PROJ, out_from_light, gl_ViewIndex);
#else
    gl_Position = OMNI_VIEW_PROJ * vec4(out_from_light, 1.0);
#endif
}
