//! Vertices, meshes, and what every generated surface is made with: grids of quads and
//! triangles wound by their normals (mesh.rs's shapes and the teapot's patches).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    /// Texture coordinates (the blinn-phong model's albedo and normal maps).
    pub uv: [f32; 2],
    /// xyz: tangent along +u, orthogonal to the normal; w: ±1, the bitangent's handedness
    /// (bitangent = w · normal × tangent), for normal mapping.
    pub tangent: [f32; 4],
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub vertices: Vec<Vertex>,
    pub indices: Vec<u32>,
}

/// A vertex without its tangent (`compute_tangents` adds it once the mesh is complete).
pub(crate) fn vertex_uv(p: Vec3, n: Vec3, uv: [f32; 2]) -> Vertex {
    Vertex { position: p.to_array(), normal: n.normalize().to_array(), uv, tangent: [0.0; 4] }
}

/// Indices of a (rows+1)×(cols+1) vertex grid as triangles, two per cell (winding is fixed
/// afterwards by `orient_triangles_to_normals`).
pub(crate) fn grid_indices(base: u32, rows: u32, cols: u32, out: &mut Vec<u32>) {
    let stride = cols + 1;
    for r in 0..rows {
        for c in 0..cols {
            let a = base + r * stride + c;
            let b = a + 1;
            let d = a + stride;
            let e = d + 1;
            out.extend_from_slice(&[a, d, b, b, d, e]);
        }
    }
}

/// The triangle's normal as wound, its length twice the triangle's area.
pub(crate) fn triangle_normal(mesh: &Mesh, tri: &[u32]) -> Vec3 {
    let p = |i: u32| Vec3::from(mesh.vertices[i as usize].position);
    (p(tri[1]) - p(tri[0])).cross(p(tri[2]) - p(tri[0]))
}

/// Drop triangles of zero area (the collapsed cells at a sphere's poles).
fn drop_degenerate(mut mesh: Mesh) -> Mesh {
    let mut kept = Vec::with_capacity(mesh.indices.len());
    for tri in mesh.indices.chunks_exact(3) {
        if triangle_normal(&mesh, tri).length_squared() > 1e-14 {
            kept.extend_from_slice(tri);
        }
    }
    mesh.indices = kept;
    mesh
}

/// Wind every triangle counter-clockwise about its vertices' mean normal. For generated
/// surfaces whose parameterisation may be mirrored (reflected teapot patches, the knot's
/// frame) this is simpler and safer than tracking handedness by hand.
pub(crate) fn orient_triangles_to_normals(mesh: &mut Mesh) -> Mesh {
    let mut mesh = drop_degenerate(std::mem::take(mesh));
    for t in 0..mesh.indices.len() / 3 {
        let tri = &mesh.indices[t * 3..t * 3 + 3];
        let mean: Vec3 = tri.iter().map(|&i| Vec3::from(mesh.vertices[i as usize].normal)).sum();
        if triangle_normal(&mesh, tri).dot(mean) < 0.0 {
            mesh.indices.swap(t * 3 + 1, t * 3 + 2);
        }
    }
    mesh
}
