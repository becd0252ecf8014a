// The transparent resolve: the opaque pass left linear HDR (alpha 0 where no surface is);
// per pixel the transparent layers are lit and blended over it back to front (layers.glsl)
// and the result encoded into the colour target, as tonemap.comp would have. The includer
// defines CLUSTERED where the technique has cluster lists.
#include "common/common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

#include "common/scene_bindings.glsl"
layout(set = 0, binding = 5) uniform sampler2D hdr_image;
layout(set = 0, binding = 8, rgba8) uniform writeonly image2D out_image;
#include "common/textures.glsl"
#include "common/lighting.glsl"
#define LAYER_BINDING 20
#include "transparency/layers.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) {
        return;
    }
    vec4 hdr = texelFetch(hdr_image, p, 0);
    imageStore(out_image, p, layered_output(p, vec2(p) + 0.5, hdr.rgb, hdr.a == 0.0, frame.exposure.x));
}
