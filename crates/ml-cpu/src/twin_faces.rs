//! Twin faces: a double-sided surface modelled with both of its faces — each triangle also
//! present with its corners in reverse order, at the same positions (foliage exporters write
//! leaves so, often sharing the vertices and their normals).
//!
//! glTF draws a double-sided material's back faces with the normal reversed, so at every
//! point of such a leaf two triangles meet at exactly the same depth with opposite normals:
//! which one a pixel shows is a tie, and each raster breaks ties its own way (the first drawn,
//! the lowest id, a rounding) — the image would change with the technique. The rule here is
//! the one a viewer expects: where the two faces coincide, the face turned toward the viewer
//! is seen. It holds exactly when the twins are drawn single-sided (each face from its own
//! side, the other culled), so the loader moves them into a single-sided mesh of their own;
//! everything else of the material stays double-sided.

use crate::geometry::Mesh;
use std::collections::HashSet;

/// A triangle's corners as bit patterns, turned so that the smallest comes first (the same
/// key for every rotation of the same winding).
type Corners = [[u32; 3]; 3];

fn corners(mesh: &Mesh, tri: &[u32]) -> Corners {
    tri.iter().map(|&i| mesh.vertices[i as usize].position.map(f32::to_bits)).collect::<Vec<_>>().try_into().expect("three corners")
}

fn turned(c: Corners) -> Corners {
    let first = (0..3).min_by_key(|&k| c[k]).expect("three corners");
    [c[first], c[(first + 1) % 3], c[(first + 2) % 3]]
}

fn reversed(c: Corners) -> Corners {
    turned([c[0], c[2], c[1]])
}

/// `mesh`'s triangles split into (the others, the twins): a triangle is a twin where another
/// triangle has its three corner positions in reverse order. Degenerate triangles (two equal
/// corners) never are. None where the mesh has no twins. Each part keeps only the vertices
/// its triangles use, in their first order.
pub fn split_twin_faces(mesh: &Mesh) -> Option<(Mesh, Mesh)> {
    let degenerate = |c: &Corners| c[0] == c[1] || c[1] == c[2] || c[0] == c[2];
    let keys: Vec<Corners> = mesh.indices.chunks_exact(3).map(|t| turned(corners(mesh, t))).collect();
    let present: HashSet<Corners> = keys.iter().copied().filter(|c| !degenerate(c)).collect();
    let twin: Vec<bool> = keys.iter().map(|c| !degenerate(c) && present.contains(&reversed(*c))).collect();
    if !twin.contains(&true) {
        return None;
    }
    let part = |want: bool| {
        let mut out = Mesh::default();
        let mut remap = vec![u32::MAX; mesh.vertices.len()];
        for (tri, _) in mesh.indices.chunks_exact(3).zip(&twin).filter(|(_, &t)| t == want) {
            for &i in tri {
                let slot = &mut remap[i as usize];
                if *slot == u32::MAX {
                    *slot = out.vertices.len() as u32;
                    out.vertices.push(mesh.vertices[i as usize]);
                }
                out.indices.push(*slot);
            }
        }
        out
    };
    Some((part(false), part(true)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vertex;

    fn vertex(x: f32, y: f32) -> Vertex {
        Vertex { position: [x, y, 0.0], normal: [0.0, 0.0, 1.0], ..Vertex::default() }
    }

    /// A unit quad (two triangles) with shared vertices, then `extra` index triples.
    fn quad_with(extra: &[u32]) -> Mesh {
        let mut indices = vec![0, 1, 2, 0, 2, 3];
        indices.extend_from_slice(extra);
        Mesh { vertices: vec![vertex(0.0, 0.0), vertex(1.0, 0.0), vertex(1.0, 1.0), vertex(0.0, 1.0)], indices }
    }

    #[test]
    fn a_mesh_without_reversed_copies_has_no_twins() {
        assert_eq!(split_twin_faces(&quad_with(&[])), None);
        // The same triangle twice, same winding (turned): not a twin.
        assert_eq!(split_twin_faces(&quad_with(&[1, 2, 0])), None);
        // Degenerate triangles reversed are not twins either.
        assert_eq!(split_twin_faces(&quad_with(&[0, 0, 1, 1, 0, 0])), None);
    }

    #[test]
    fn reversed_triangles_on_shared_or_copied_vertices_are_twins() {
        // Shared vertices: the first triangle's reverse, written from another corner.
        let (rest, twins) = split_twin_faces(&quad_with(&[2, 1, 0])).expect("twins");
        assert_eq!(twins.indices.len(), 6, "the triangle and its reverse");
        assert_eq!(rest.indices.len(), 3, "the quad's other half");
        let positions = |m: &Mesh| m.indices.iter().map(|&i| m.vertices[i as usize].position).collect::<Vec<_>>();
        assert_eq!(
            positions(&twins),
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
        );
        assert_eq!(positions(&rest), [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
        // Each part keeps only its own vertices.
        assert_eq!((twins.vertices.len(), rest.vertices.len()), (3, 3));
        // Copied vertices at the same positions with their own (reversed) normals.
        let mut m = quad_with(&[]);
        let copies: Vec<Vertex> = m.vertices.iter().map(|v| Vertex { normal: [0.0, 0.0, -1.0], ..*v }).collect();
        m.vertices.extend(copies);
        m.indices.extend([4, 6, 5, 4, 7, 6]);
        let (rest, twins) = split_twin_faces(&m).expect("twins");
        assert!(rest.indices.is_empty());
        assert_eq!(twins.indices.len(), 12);
        assert_eq!(twins.vertices.iter().filter(|v| v.normal[2] < 0.0).count(), 4, "the copies keep their normals");
    }

    #[test]
    fn a_corner_moved_by_one_ulp_is_no_twin() {
        let mut m = quad_with(&[]);
        m.vertices.push(Vertex { position: [f32::from_bits(1), 0.0, 0.0], ..m.vertices[0] });
        m.indices.extend([4, 2, 1]);
        assert_eq!(split_twin_faces(&m), None);
    }
}
