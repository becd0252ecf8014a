//! Area-weighted random points on a scene's surfaces (the `surface` light layout): every
//! triangle of every object in world space, drawn with probability proportional to its area,
//! a point uniform inside it. It takes meshes with their object-to-world transforms rather
//! than a scene, since scenes are built with the lights placed from it (`Scene::surfaces`
//! hands over a scene's objects).

use crate::mesh::Mesh;
use glam::{Mat4, Vec3};
use rand::Rng;

/// A scene's world-space triangles and their running area, to draw points from.
pub struct SurfaceSampler {
    /// Corners a, b, c of each triangle of non-zero area.
    triangles: Vec<[Vec3; 3]>,
    /// Area of triangles 0..=i.
    cumulative: Vec<f32>,
}

impl SurfaceSampler {
    /// The triangles of each mesh moved into the world by its transform (an object's); None
    /// when they have no area at all.
    pub fn new<'a>(placed: impl IntoIterator<Item = (&'a Mesh, Mat4)>) -> Option<SurfaceSampler> {
        let (mut triangles, mut cumulative, mut total) = (Vec::new(), Vec::new(), 0.0f32);
        for (mesh, transform) in placed {
            let world: Vec<Vec3> = mesh.vertices.iter().map(|v| transform.transform_point3(Vec3::from(v.position))).collect();
            for t in mesh.indices.chunks_exact(3) {
                let corners = [world[t[0] as usize], world[t[1] as usize], world[t[2] as usize]];
                let area = (corners[1] - corners[0]).cross(corners[2] - corners[0]).length() * 0.5;
                if area > 0.0 && area.is_finite() {
                    total += area;
                    triangles.push(corners);
                    cumulative.push(total);
                }
            }
        }
        (total > 0.0).then_some(SurfaceSampler { triangles, cumulative })
    }

    /// Total area of the surfaces.
    pub fn area(&self) -> f32 {
        self.cumulative.last().copied().unwrap_or(0.0)
    }

    /// A point uniform over the surfaces and the unit normal of its triangle (the side its
    /// corners turn counter-clockwise on, as every mesh winds towards its normals).
    pub fn sample(&self, rng: &mut impl Rng) -> (Vec3, Vec3) {
        let target = rng.random_range(0.0..self.area());
        let i = self.cumulative.partition_point(|&c| c <= target).min(self.triangles.len() - 1);
        let [a, b, c] = self.triangles[i];
        // Uniform in the triangle: fold the unit square's upper half onto the lower.
        let (mut u, mut v) = (rng.random::<f32>(), rng.random::<f32>());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        (a + (b - a) * u + (c - a) * v, (b - a).cross(c - a).normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::material::Material;
    use crate::mesh::MeshKind;
    use crate::scene::{Object, Scene};
    use rand::SeedableRng;

    #[test]
    fn points_fall_on_triangles_in_proportion_to_their_area() {
        let white = Material::named("white").unwrap();
        // Two planes facing +Y: one of side 2 at y = 0, one of side 6 at y = 5 (nine times the area).
        let scene = Scene::new(
            vec![
                Object::placed(MeshKind::Plane, Vec3::ZERO, 1.0, white),
                Object::placed(MeshKind::Plane, Vec3::new(0.0, 5.0, 0.0), 3.0, white),
            ],
            Vec::new(),
            Camera::seed(),
        );
        let sampler = scene.surfaces().unwrap();
        assert!((sampler.area() - 40.0).abs() < 1e-3, "{}", sampler.area());
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut high = 0;
        for _ in 0..10_000 {
            let (p, n) = sampler.sample(&mut rng);
            assert!(n.abs_diff_eq(Vec3::Y, 1e-5), "{n}");
            if p.y == 5.0 {
                assert!(p.x.abs() <= 3.0 && p.z.abs() <= 3.0);
                high += 1;
            } else {
                assert!(p.y == 0.0 && p.x.abs() <= 1.0 && p.z.abs() <= 1.0, "{p}");
            }
        }
        assert!((8_800..=9_200).contains(&high), "{high} of 10000 on the larger plane");
    }

    #[test]
    fn a_scene_without_area_has_no_surfaces() {
        let flat = Object {
            transform: glam::Mat4::from_scale(Vec3::ZERO),
            ..Object::placed(MeshKind::Cube, Vec3::ZERO, 1.0, Material::named("white").unwrap())
        };
        assert!(Scene::new(vec![flat], Vec::new(), Camera::seed()).surfaces().is_none());
        assert!(Scene::new(Vec::new(), Vec::new(), Camera::seed()).surfaces().is_none());
    }
}
