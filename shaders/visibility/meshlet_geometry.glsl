// A meshlet's triangles as the GPU-driven passes read them (meshlets.rs): per meshlet, its
// vertices (indices into the scene's vertex buffer) and its triangles (three 8-bit indices
// into those vertices, packed in a word). The includer declares `meshlet_vertices[]` and
// `meshlet_triangles[]` (MeshletVertexBuffer, MeshletTriangleBuffer).
// Needs common.glsl.

#ifndef MANYLIGHTS_MESHLET_GEOMETRY_GLSL
#define MANYLIGHTS_MESHLET_GEOMETRY_GLSL

// Triangle `t`'s corners as indices into the meshlet's vertices (0..63).
uvec3 meshlet_corners(Meshlet m, uint t) {
    uint packed = meshlet_triangles[m.triangles.x + t];
    return uvec3(packed, packed >> 8u, packed >> 16u) & 0xffu;
}

// Triangle `t`'s corners as indices into the scene's vertex buffer.
uvec3 meshlet_triangle(Meshlet m, uint t) {
    uvec3 local = meshlet_corners(m, t) + m.triangles.z;
    return uvec3(meshlet_vertices[local.x], meshlet_vertices[local.y], meshlet_vertices[local.z]);
}

#endif
