#version 450
// Legend of the cluster-heat debug view: a rectangle at the bottom left of the image,
// made from the vertex index (no vertex buffer).

layout(location = 0) out vec2 out_uv;

// Corners in NDC (Vulkan: +y is down, so y = 0.95 is near the bottom).
const vec2 LEGEND_MIN = vec2(-0.96, 0.80);
const vec2 LEGEND_MAX = vec2(-0.30, 0.96);

void main() {
    const vec2 corners[6] = vec2[6](vec2(0, 0), vec2(0, 1), vec2(1, 0), vec2(1, 0), vec2(0, 1), vec2(1, 1));
    out_uv = corners[gl_VertexIndex];
    gl_Position = vec4(mix(LEGEND_MIN, LEGEND_MAX, out_uv), 0.0, 1.0);
}
