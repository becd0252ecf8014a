//! Meshlets: every mesh split into clusters of at most 64 vertices and 124 triangles, each
//! with a bounding sphere and a back-face cone (meshoptimizer builds both), so that the GPU
//! can cull geometry in pieces small enough that what survives is close to what is seen.
//!
//! The scene's geometry for the GPU-driven passes: one vertex buffer of every mesh; per
//! meshlet, its vertices (indices into that buffer, ≤ 64) and its triangles (three 8-bit
//! indices into the meshlet's vertices, packed in 32 bits); the meshlets; an instance per
//! object; and a meshlet instance per (object, meshlet of its mesh). A meshlet instance's id
//! and a triangle's index in its meshlet make the 32-bit visibility id; a draw slot and a
//! meshlet vertex make a 32-bit index of the compacted index buffer
//! (docs/DESIGN.md#visibility-buffer).

use crate::geometry::{Mesh, Vertex};
use crate::gpu_types::{Instance, Meshlet, INSTANCE_CONE_CULLING, INSTANCE_DOUBLE_SIDED, INSTANCE_MASKED, INSTANCE_MIRRORED};
use crate::scene::Scene;
use glam::{Mat3, Mat4, Vec3};
use thiserror::Error;

/// The most vertices of a meshlet (what mesh-shading hardware favours; fits a workgroup).
pub const MAX_VERTICES: usize = 64;
/// Low bits of a compacted index: the vertex in its meshlet.
pub const VERTEX_BITS: u32 = 6;
/// The most triangles of a meshlet: below 128, so a triangle's index takes 7 bits.
pub const MAX_TRIANGLES: usize = 124;
/// Low bits of a visibility id: the triangle in its meshlet.
pub const TRIANGLE_BITS: u32 = 7;
/// The most meshlet instances a scene may have: the id's other 25 bits.
pub const MAX_MESHLET_INSTANCES: usize = 1 << (32 - TRIANGLE_BITS);
/// Mesh-shading practice: a little weight on cone tightness makes back-face culling pay
/// without making meshlets much less compact.
const CONE_WEIGHT: f32 = 0.25;

#[derive(Debug, Error, PartialEq)]
pub enum MeshletError {
    #[error(
        "the scene has {count} meshlet instances (objects × meshlets of their meshes); a visibility id names at most {MAX_MESHLET_INSTANCES}"
    )]
    TooManyInstances { count: usize },
}

/// A mesh's meshlets (their first triangle and first vertex count from 0), their vertices
/// as mesh-local vertex indices and their triangles as packed meshlet-local indices, meshlet
/// after meshlet.
pub struct MeshMeshlets {
    pub meshlets: Vec<Meshlet>,
    pub vertices: Vec<u32>,
    pub triangles: Vec<u32>,
}

/// Three meshlet-local vertex indices (< 64) in one word: a | b << 8 | c << 16.
pub fn pack_triangle(t: [u8; 3]) -> u32 {
    t[0] as u32 | (t[1] as u32) << 8 | (t[2] as u32) << 16
}

impl MeshMeshlets {
    /// Triangle `t` of `meshlet` as three indices into what `vertices` indexes.
    pub fn triangle(&self, meshlet: &Meshlet, t: u32) -> [u32; 3] {
        corners(&self.vertices, &self.triangles, meshlet, t)
    }
}

fn corners(vertices: &[u32], triangles: &[u32], meshlet: &Meshlet, t: u32) -> [u32; 3] {
    let packed = triangles[(meshlet.triangles[0] + t) as usize];
    [0, 8, 16].map(|shift| vertices[(meshlet.triangles[2] + ((packed >> shift) & 0xff)) as usize])
}

/// Split `mesh` into meshlets, with bounds in object space.
pub fn build(mesh: &Mesh) -> MeshMeshlets {
    let bytes: &[u8] = bytemuck::cast_slice(&mesh.vertices);
    let adapter = meshopt::VertexDataAdapter::new(bytes, std::mem::size_of::<Vertex>(), std::mem::offset_of!(Vertex, position))
        .expect("the vertex layout has a position");
    let built = meshopt::build_meshlets(&mesh.indices, &adapter, MAX_VERTICES, MAX_TRIANGLES, CONE_WEIGHT);
    let mut out = MeshMeshlets { meshlets: Vec::with_capacity(built.len()), vertices: Vec::new(), triangles: Vec::new() };
    for m in built.iter() {
        let b = meshopt::compute_meshlet_bounds(m, &adapter);
        let (first_triangle, first_vertex) = (out.triangles.len() as u32, out.vertices.len() as u32);
        out.vertices.extend_from_slice(m.vertices);
        out.triangles.extend(m.triangles.chunks_exact(3).map(|t| pack_triangle([t[0], t[1], t[2]])));
        out.meshlets.push(Meshlet {
            center_radius: [b.center[0], b.center[1], b.center[2], b.radius],
            cone_axis_cutoff: [b.cone_axis[0], b.cone_axis[1], b.cone_axis[2], b.cone_cutoff],
            cone_apex: [b.cone_apex[0], b.cone_apex[1], b.cone_apex[2], 0.0],
            triangles: [first_triangle, (m.triangles.len() / 3) as u32, first_vertex, m.vertices.len() as u32],
        });
    }
    out
}

/// The scene's geometry as the GPU-driven passes read it.
#[derive(Default)]
pub struct SceneMeshlets {
    /// Every mesh's vertices, mesh after mesh (`Scene::mesh_kinds` order).
    pub vertices: Vec<Vertex>,
    /// Every meshlet's vertices: indices into `vertices`.
    pub meshlet_vertices: Vec<u32>,
    /// Every meshlet's triangles: three indices into its vertices, packed.
    pub meshlet_triangles: Vec<u32>,
    pub meshlets: Vec<Meshlet>,
    /// Per object (same index): where its meshlets and meshlet instances are, its bounds.
    pub instances: Vec<Instance>,
    /// Per meshlet instance: (object, meshlet). Its index is the visibility id's high bits.
    pub meshlet_instances: Vec<[u32; 2]>,
    /// Triangles of every object together (what drawing everything draws).
    pub triangles: u64,
}

impl SceneMeshlets {
    pub fn build(scene: &Scene) -> Result<SceneMeshlets, MeshletError> {
        let mut s = SceneMeshlets::default();
        // Per mesh kind: (first meshlet, meshlet count, object-space bounding sphere, triangles).
        let mut per_mesh = Vec::new();
        let kinds = scene.mesh_kinds();
        for &kind in &kinds {
            let mesh = scene.mesh(kind).unwrap_or_default();
            let base = s.vertices.len() as u32;
            let built = build(&mesh);
            let (first_triangle, first_vertex) = (s.meshlet_triangles.len() as u32, s.meshlet_vertices.len() as u32);
            let first_meshlet = s.meshlets.len() as u32;
            s.meshlet_vertices.extend(built.vertices.iter().map(|i| i + base));
            s.meshlet_triangles.extend_from_slice(&built.triangles);
            s.meshlets.extend(built.meshlets.iter().map(|m| {
                let mut m = *m;
                m.triangles[0] += first_triangle;
                m.triangles[2] += first_vertex;
                m
            }));
            per_mesh.push((first_meshlet, built.meshlets.len() as u32, bounding_sphere(&mesh), (mesh.indices.len() / 3) as u64));
            s.vertices.extend_from_slice(&mesh.vertices);
        }
        // Each object's mesh (kinds holds every object's; a map: as many meshes as objects).
        let index: std::collections::HashMap<crate::mesh::MeshKind, usize> = kinds.iter().enumerate().map(|(i, &k)| (k, i)).collect();
        let mesh_of: Vec<usize> = scene.objects.iter().map(|o| index[&o.mesh]).collect();
        let count: usize = mesh_of.iter().map(|&m| per_mesh[m].1 as usize).sum();
        if count > MAX_MESHLET_INSTANCES {
            return Err(MeshletError::TooManyInstances { count });
        }
        s.meshlet_instances.reserve(count);
        for (object, (o, &m)) in scene.objects.iter().zip(&mesh_of).enumerate() {
            let (first, n, (centre, radius), triangles) = per_mesh[m];
            let placement = Placement::of(o.transform);
            let world = o.transform.transform_point3(centre);
            s.instances.push(Instance {
                bounds: world.extend(radius * placement.max_scale).to_array(),
                scale: [placement.max_scale, 0.0, 0.0, 0.0],
                meshlets: [first, n, s.meshlet_instances.len() as u32, surface_flags(o, placement.flags)],
                surface: [o.textures.bits(), 0, 0, 0],
            });
            s.meshlet_instances.extend((first..first + n).map(|m| [object as u32, m]));
            s.triangles += triangles;
        }
        Ok(s)
    }

    /// Triangle `t` of meshlet `meshlet` as three indices into `vertices`.
    pub fn triangle(&self, meshlet: u32, t: u32) -> [u32; 3] {
        corners(&self.meshlet_vertices, &self.meshlet_triangles, &self.meshlets[meshlet as usize], t)
    }
}

/// The `INSTANCE_*` bits of object `o` placed with `placement` bits: a double-sided object's
/// back faces are drawn, so no cone culls its meshlets.
fn surface_flags(o: &crate::scene::Object, placement: u32) -> u32 {
    let mut flags = placement;
    if o.extras.double_sided {
        flags = (flags & !INSTANCE_CONE_CULLING) | INSTANCE_DOUBLE_SIDED;
    }
    if o.extras.masked() {
        flags |= INSTANCE_MASKED;
    }
    flags
}

/// What an object's transform does to bounds and cones.
struct Placement {
    /// The largest factor by which it stretches a length (spheres grow by it).
    max_scale: f32,
    /// `INSTANCE_*` bits: cones stay valid under rotation, uniform scale and mirroring only
    /// (a mirror turns them around); other transforms cull no back faces by cone.
    flags: u32,
}

impl Placement {
    fn of(transform: Mat4) -> Placement {
        let m = Mat3::from_mat4(transform);
        let lengths = [m.x_axis.length(), m.y_axis.length(), m.z_axis.length()];
        let max_scale = lengths.into_iter().fold(0.0, f32::max);
        let tolerance = 1e-4 * max_scale;
        let uniform = lengths.iter().all(|l| (l - max_scale).abs() <= tolerance);
        let orthogonal =
            [m.x_axis.dot(m.y_axis), m.y_axis.dot(m.z_axis), m.z_axis.dot(m.x_axis)].iter().all(|d| d.abs() <= tolerance * max_scale);
        let mut flags = 0;
        if uniform && orthogonal && max_scale > 0.0 {
            flags |= INSTANCE_CONE_CULLING;
        }
        if m.determinant() < 0.0 {
            flags |= INSTANCE_MIRRORED;
        }
        Placement { max_scale, flags }
    }
}

/// A sphere around every vertex: the box's centre and the farthest vertex from it.
fn bounding_sphere(mesh: &Mesh) -> (Vec3, f32) {
    let positions = mesh.vertices.iter().map(|v| Vec3::from(v.position));
    let (lo, hi) = positions.clone().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(p), hi.max(p)));
    if lo.x > hi.x {
        return (Vec3::ZERO, 0.0);
    }
    let centre = (lo + hi) * 0.5;
    (centre, positions.map(|p| p.distance(centre)).fold(0.0, f32::max))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshKind;
    use std::collections::HashSet;

    /// Every triangle of the mesh appears in exactly one meshlet, with its winding (a
    /// rotation of its three indices), and every meshlet keeps within the limits.
    #[test]
    fn meshlets_hold_every_triangle_once() {
        for kind in MeshKind::ALL {
            let mesh = kind.build();
            let m = build(&mesh);
            let canonical = |t: &[u32]| {
                let k = (0..3).min_by_key(|&i| t[i]).unwrap();
                [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
            };
            let mut expected: Vec<[u32; 3]> = mesh.indices.chunks_exact(3).map(canonical).collect();
            let mut got: Vec<[u32; 3]> =
                m.meshlets.iter().flat_map(|ml| (0..ml.triangles[1]).map(|t| canonical(&m.triangle(ml, t)))).collect();
            expected.sort();
            got.sort();
            assert_eq!(got, expected, "{kind:?}");
            let (mut next_triangle, mut next_vertex) = (0, 0);
            for meshlet in &m.meshlets {
                let [first, triangles, first_vertex, vertices] = meshlet.triangles;
                assert_eq!((first, first_vertex), (next_triangle, next_vertex), "{kind:?}: meshlets follow each other");
                assert!(triangles >= 1 && triangles as usize <= MAX_TRIANGLES);
                assert!(vertices as usize <= MAX_VERTICES && vertices <= 1 << VERTEX_BITS, "{kind:?}: {vertices} vertices");
                let used: HashSet<u32> = (0..triangles).flat_map(|t| m.triangle(meshlet, t)).collect();
                assert_eq!(used.len(), vertices as usize, "{kind:?}: every meshlet vertex is used");
                next_triangle = first + triangles;
                next_vertex = first_vertex + vertices;
            }
            assert_eq!((next_triangle as usize, next_vertex as usize), (m.triangles.len(), m.vertices.len()));
        }
    }

    /// Bounds are conservative: every vertex of a meshlet is inside its sphere, and every
    /// triangle faces away from an eye that the cone says sees only back faces.
    #[test]
    fn bounds_and_cones_are_conservative() {
        for kind in [MeshKind::Sphere, MeshKind::TorusKnot, MeshKind::Teapot, MeshKind::Cube, MeshKind::Room] {
            let mesh = kind.build();
            let m = build(&mesh);
            let mut culled = 0;
            let p = |i: u32| Vec3::from(mesh.vertices[i as usize].position);
            let eyes: Vec<Vec3> = (0..64)
                .map(|i| {
                    let a = i as f32 * 2.399;
                    Vec3::new(a.cos(), (i as f32 / 32.0) - 1.0, a.sin()) * (1.5 + (i % 5) as f32)
                })
                .collect();
            for meshlet in &m.meshlets {
                let c = Vec3::from_slice(&meshlet.center_radius[..3]);
                let tris: Vec<u32> = (0..meshlet.triangles[1]).flat_map(|t| m.triangle(meshlet, t)).collect();
                for &i in &tris {
                    assert!(p(i).distance(c) <= meshlet.center_radius[3] * (1.0 + 1e-5) + 1e-6, "{kind:?}: vertex outside");
                }
                let axis = Vec3::from_slice(&meshlet.cone_axis_cutoff[..3]);
                let apex = Vec3::from_slice(&meshlet.cone_apex[..3]);
                for &eye in &eyes {
                    if (apex - eye).normalize().dot(axis) < meshlet.cone_axis_cutoff[3] {
                        continue;
                    }
                    culled += 1;
                    for t in tris.chunks_exact(3) {
                        let n = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
                        assert!(n.dot(eye - p(t[0])) <= 1e-6, "{kind:?}: a culled triangle faces the eye");
                    }
                }
            }
            // A cube is one meshlet facing every way: no eye sees only its back.
            assert!(culled > 0 || matches!(kind, MeshKind::Cube | MeshKind::Room), "{kind:?}: no eye sees only back faces of any meshlet");
        }
    }

    #[test]
    fn scene_meshlets_index_one_vertex_buffer() {
        let scene =
            Scene::seed(MeshKind::Teapot, crate::material::Material::named("gold").unwrap(), &crate::lights::LightParams::seed_default())
                .unwrap();
        let s = SceneMeshlets::build(&scene).unwrap();
        assert_eq!(s.instances.len(), scene.objects.len());
        assert!(s.meshlet_vertices.iter().all(|&i| (i as usize) < s.vertices.len()));
        // Every meshlet triangle names a vertex of the scene.
        for (k, meshlet) in s.meshlets.iter().enumerate() {
            for t in 0..meshlet.triangles[1] {
                assert!(s.triangle(k as u32, t).iter().all(|&i| (i as usize) < s.vertices.len()));
            }
        }
        let per_object = s.instances[0].meshlets[1] as usize;
        assert_eq!(s.meshlet_instances.len(), per_object * scene.objects.len());
        for (id, &[object, meshlet]) in s.meshlet_instances.iter().enumerate() {
            let inst = &s.instances[object as usize];
            assert_eq!(inst.meshlets[2] + (meshlet - inst.meshlets[0]), id as u32);
        }
    }

    #[test]
    fn placements_say_where_cones_hold() {
        let similar = Mat4::from_scale_rotation_translation(Vec3::splat(2.0), glam::Quat::from_rotation_y(0.7), Vec3::X);
        assert_eq!(Placement::of(similar).flags, INSTANCE_CONE_CULLING);
        assert_eq!(Placement::of(similar).max_scale, 2.0);
        let mirrored = similar * Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        assert_eq!(Placement::of(mirrored).flags, INSTANCE_CONE_CULLING | INSTANCE_MIRRORED);
        let stretched = Mat4::from_scale(Vec3::new(1.0, 3.0, 1.0));
        assert_eq!(Placement::of(stretched).flags, 0);
        assert_eq!(Placement::of(stretched).max_scale, 3.0);
    }

    #[test]
    fn double_sided_objects_are_never_cone_culled_and_masks_are_flagged() {
        use crate::scene::{AlphaMode, MaterialExtras, Object};
        let mut o = Object::placed(crate::mesh::MeshKind::Plane, Vec3::ZERO, 1.0, crate::material::Material::named("white").unwrap());
        assert_eq!(surface_flags(&o, INSTANCE_CONE_CULLING), INSTANCE_CONE_CULLING);
        o.extras = MaterialExtras { double_sided: true, ..MaterialExtras::default() };
        assert_eq!(surface_flags(&o, INSTANCE_CONE_CULLING | INSTANCE_MIRRORED), INSTANCE_DOUBLE_SIDED | INSTANCE_MIRRORED);
        o.extras = MaterialExtras { alpha_mode: AlphaMode::Mask { cutoff: 0.3 }, ..MaterialExtras::default() };
        assert_eq!(surface_flags(&o, INSTANCE_CONE_CULLING), INSTANCE_CONE_CULLING | INSTANCE_MASKED);
        o.extras = MaterialExtras { alpha_mode: AlphaMode::Blend, ..MaterialExtras::default() };
        assert_eq!(surface_flags(&o, 0), INSTANCE_MASKED);
    }
}
