// Set 0 as every shading path sees it: the frame's uniforms, the lights (point and directional), the objects and, with
// CLUSTERED defined, the cluster lists, with LIGHT_GRID the light grid's. Rust binds them by these names, reflected from the
// SPIR-V (descriptors.rs).

#ifndef MANYLIGHTS_SCENE_BINDINGS_GLSL
#define MANYLIGHTS_SCENE_BINDINGS_GLSL

FRAME_BLOCK(0);
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
// frame.directional_count of them (a one-element stand-in where there are none).
layout(std430, set = 0, binding = 19) readonly buffer DirectionalLightBuffer { DirectionalLightData directional_lights[]; };
#ifdef CLUSTERED
layout(std430, set = 0, binding = 2) readonly buffer ClusterRangeBuffer { ClusterRange cluster_ranges[]; };
layout(std430, set = 0, binding = 3) readonly buffer LightIndexBuffer { uint light_indices[]; };
#endif
// The shadow rays' hierarchy (shadows/shadow_rays.glsl): the top level over the objects, every
// mesh's bottom level, their triangles and the objects' instances. One-element stand-ins
// where point lights cast no shadow rays.
layout(std430, set = 0, binding = 40) readonly buffer RayTopBuffer { RayNode ray_top[]; };
layout(std430, set = 0, binding = 41) readonly buffer RayNodeBuffer { RayNode ray_nodes[]; };
layout(std430, set = 0, binding = 42) readonly buffer RayTriangleBuffer { RayTriangle ray_triangles[]; };
layout(std430, set = 0, binding = 43) readonly buffer RayInstanceBuffer { RayInstance ray_instances[]; };
// Per triangle of the bottom levels, its corners' texture coordinates (alpha masks).
layout(std430, set = 0, binding = 44) readonly buffer RayUvBuffer { vec2 ray_uvs[]; };
#ifdef LIGHT_GRID
// The light grid's lists' ends (list 0 the wide lights', then a list per marked cell) and per
// 32 cells their marks and the list of the first marked one (light_grid/light_grid.glsl).
layout(std430, set = 0, binding = 30) readonly buffer LightGridListBuffer { uint grid_lists[]; };
layout(std430, set = 0, binding = 31) readonly buffer LightGridOccupancyBuffer { uvec2 grid_occupancy[]; };
#endif

#endif
