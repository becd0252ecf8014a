#version 450
#extension GL_GOOGLE_include_directive : require
// The probe's fragment half: one full-screen triangle (fullscreen.vert), one pixel each.
#include "probe/stage_probe.glsl"

layout(location = 0) out vec4 out_color;

void main() {
    out_color = probe_pixel(ivec2(gl_FragCoord.xy));
}
