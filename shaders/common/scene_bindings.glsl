// Set 0 as every shading path sees it: the frame's uniforms, the lights, the objects and, with
// CLUSTERED defined, the cluster lists, with LIGHT_GRID the light grid's. Rust binds them by these names, reflected from the
// SPIR-V (descriptors.rs).

#ifndef MANYLIGHTS_SCENE_BINDINGS_GLSL
#define MANYLIGHTS_SCENE_BINDINGS_GLSL

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, set = 0, binding = 1) readonly buffer LightBuffer { PointLight lights[]; };
layout(std430, set = 0, binding = 4) readonly buffer ObjectBuffer { ObjectData objects[]; };
layout(std430, set = 0, binding = 10) readonly buffer LightConeBuffer { LightCone light_cones[]; };
#ifdef CLUSTERED
layout(std430, set = 0, binding = 2) readonly buffer ClusterRangeBuffer { ClusterRange cluster_ranges[]; };
layout(std430, set = 0, binding = 3) readonly buffer LightIndexBuffer { uint light_indices[]; };
#endif
#ifdef LIGHT_GRID
layout(std430, set = 0, binding = 20) readonly buffer LightGridCellBuffer { uint grid_cell_ends[]; };
layout(std430, set = 0, binding = 21) readonly buffer LightGridBlockBuffer { uvec2 grid_blocks[]; };
layout(std430, set = 0, binding = 22) readonly buffer LightGridIndexBuffer { uint grid_lights[]; };
#endif

#endif
