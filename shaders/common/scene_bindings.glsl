// Set 0 as every shading path sees it: the frame's uniforms, the lights, the objects and, with
// CLUSTERED defined, the cluster lists, with LIGHT_GRID the light grid's. Rust binds them by these names, reflected from the
// SPIR-V (descriptors.rs).

#ifndef MANYLIGHTS_SCENE_BINDINGS_GLSL
#define MANYLIGHTS_SCENE_BINDINGS_GLSL

layout(set = 0, binding = 0) uniform FrameBlock { FrameUniforms frame; };
#ifdef LIGHT_GRID
// The light grid's lists: each light as it is this frame, list after list
// (light_grid/light_grid.glsl): position and radius, colour, index in the scene (its spot
// cone's).
layout(std430, set = 0, binding = 34) readonly buffer LightGridPositionBuffer { vec4 grid_light_positions[]; };
layout(std430, set = 0, binding = 35) readonly buffer LightGridColorBuffer { vec4 grid_light_colors[]; };
layout(std430, set = 0, binding = 32) readonly buffer LightGridIndexBuffer { uint grid_scene_index[]; };
#else
layout(std430, set = 0, binding = 1) readonly buffer LightBuffer { PointLight lights[]; };
#endif
layout(std430, set = 0, binding = 4) readonly buffer ObjectBuffer { ObjectData objects[]; };
layout(std430, set = 0, binding = 10) readonly buffer LightConeBuffer { LightCone light_cones[]; };
#ifdef CLUSTERED
layout(std430, set = 0, binding = 2) readonly buffer ClusterRangeBuffer { ClusterRange cluster_ranges[]; };
layout(std430, set = 0, binding = 3) readonly buffer LightIndexBuffer { uint light_indices[]; };
#endif
#ifdef LIGHT_GRID
// The light grid's lists' ends (list 0 the wide lights', then a list per marked cell) and per
// 32 cells their marks and the list of the first marked one (light_grid/light_grid.glsl).
layout(std430, set = 0, binding = 30) readonly buffer LightGridListBuffer { uint grid_lists[]; };
layout(std430, set = 0, binding = 31) readonly buffer LightGridOccupancyBuffer { uvec2 grid_occupancy[]; };
#endif

#endif
