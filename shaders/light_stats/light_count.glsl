// The light counts (`render --light-stats`): for every pixel with a surface, how many lights
// the light loop tests there — the light grid's lists near it, walked by the lighting's own
// walk (GRID_FOR_LIGHTS) — and how many of them reach the point (it lies inside the light's sphere).
// Their ratio is what light culling wastes; a thread per pixel, the sums per 8×4 work group
// for the host (light_stats/light_count.rs adds them up): 32 pixels of at most 2^26 lights
// each (the most `--lights` takes) fit one 32-bit word.
//
// The includer defines OPAQUE_DEPTH_BUFFER for the compute raster's 64-bit buffer.
#define LIGHT_GRID 1
#include "common/common.glsl"

layout(local_size_x = 8, local_size_y = 4) in;

#include "common/scene_bindings.glsl"
#include "common/textures.glsl"
#include "common/lighting.glsl"
#include "common/opaque_depth.glsl"

// Per work group (row-major over the dispatch): x: pixels with a surface, y: lights tested,
// z: lights reaching; w: unused.
layout(std430, set = 0, binding = 14) writeonly buffer LightCountBuffer { uvec4 light_counts[]; };

shared uint group_pixels;
shared uint group_tested;
shared uint group_reached;

uint tested_here;
uint reached_here;

// Counts the light at `position_radius` at `world`.
void count_light(vec4 position_radius, vec3 world) {
    tested_here++;
    vec3 d = position_radius.xyz - world;
    if (dot(d, d) < position_radius.w * position_radius.w) {
        reached_here++;
    }
}

void main() {
    if (gl_LocalInvocationIndex == 0u) {
        group_pixels = 0u;
        group_tested = 0u;
        group_reached = 0u;
    }
    barrier();
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    tested_here = 0u;
    reached_here = 0u;
    if (p.x < int(frame.viewport.x) && p.y < int(frame.viewport.y)) {
        float z = opaque_depth_at(p);
        if (z < 1.0) {
            vec2 frag_xy = vec2(p) + 0.5;
            vec3 world = world_from_depth(frag_xy, z);
            GRID_FOR_LIGHTS(count_light(grid_light_positions[k_], world);)
            atomicAdd(group_pixels, 1u);
            atomicAdd(group_tested, tested_here);
            atomicAdd(group_reached, reached_here);
        }
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
        light_counts[group] = uvec4(group_pixels, group_tested, group_reached, 0u);
    }
}
