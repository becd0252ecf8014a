// The transparent resolve's lighting: a thread per node of the lists lights it where it lies
// (layers.glsl light_layer) — the same light loop, cluster lookup, shading model and shadows
// as the opaque surfaces. The nodes lie in the order their fragments were drawn, so a
// subgroup's nodes are neighbours on one surface and share their clusters' lights; the work
// groups stride through however many nodes the build kept. The includer defines CLUSTERED
// where the technique has cluster lists, LIGHT_GRID where it has the light grid.
#include "common/common.glsl"

layout(local_size_x = 256) in;

#include "common/scene_bindings.glsl"
#include "common/textures.glsl"
#include "common/lighting.glsl"
#define LAYER_BINDING 20
#include "transparency/layers.glsl"

void main() {
    uint kept = min(layer_counts.x, layer_capacity());
    for (uint node = gl_GlobalInvocationID.x; node < kept; node += gl_NumWorkGroups.x * gl_WorkGroupSize.x) {
        light_layer(node);
    }
}
