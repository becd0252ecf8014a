//! The CPU ray test of point-light shadows: at which pixels of a scene of spheres, cubes and
//! rooms it is sure which lights see the surface (away from shadow edges by more than the
//! shadow filter, the normal offset and the depth bias reach), and which.

use glam::{Vec3, Vec4};
use ml_cpu::camera::Camera;
use ml_cpu::omni_shadow::{first_hit, light_sight, solids, Sight, Solid};
use ml_cpu::scene::Scene;

/// Margin of the ray test around shadow edges, in cube texels at the point's distance: the
/// 3×3 tent reaches 1.5 texels, the normal offset 1.5, the depth bias 1.
pub const MARGIN_TEXELS: f32 = 4.0;

/// The ray through sub-pixel position (x, y) of a `size`² image.
pub fn ray(camera: &Camera, x: f32, y: f32, size: u32) -> (Vec3, Vec3) {
    let inv = (camera.projection(1.0) * camera.view()).inverse();
    let ndc = |v: f32| v / size as f32 * 2.0 - 1.0;
    let unproject = |z: f32| {
        let p = inv * Vec4::new(ndc(x), ndc(y), z, 1.0);
        p.truncate() / p.w
    };
    let near = unproject(0.0);
    (near, (unproject(1.0) - near).normalize())
}

/// Per pixel of a `size`² image, where the ray test is sure which lights see the surface
/// (shadow cubes of `cube`² texels a face): which lights do.
pub fn sure_pixels(scene: &Scene, size: u32, cube: u32) -> Vec<((u32, u32), Vec<bool>)> {
    let solids: Vec<Solid> = solids(scene).expect("scene of spheres, cubes and rooms");
    let mut out = Vec::new();
    for y in 0..size {
        for x in 0..size {
            let hit = |dx: f32, dy: f32| {
                let (o, d) = ray(&scene.camera, x as f32 + 0.5 + dx, y as f32 + 0.5 + dy, size);
                first_hit(&solids, o, d).map(|(i, t, n)| (i, o + d * t, n))
            };
            let Some((solid, point, normal)) = hit(0.0, 0.0) else { continue };
            // Not on a silhouette or an edge: the pixel's corners see the same face.
            let corners = [(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)];
            if !corners.iter().all(|&(dx, dy)| hit(dx, dy).is_some_and(|(s, _, n)| s == solid && n == normal)) {
                continue;
            }
            let sights: Vec<Sight> = scene
                .lights
                .iter()
                .map(|l| {
                    let light = Vec3::from_slice(&l.position_radius[..3]);
                    let margin = MARGIN_TEXELS * point.distance(light) * 2.0 / cube as f32;
                    light_sight(&solids, point, normal, light, margin)
                })
                .collect();
            if sights.iter().all(|&s| s != Sight::Unsure) {
                out.push(((x, y), sights.iter().map(|&s| s == Sight::Lit).collect()));
            }
        }
    }
    out
}
