//! Random scenes that stress light culling (used by tests and benchmarks): cameras anywhere
//! in the light box, lights with radii from 0.2 to 40 (so cameras sit inside light spheres),
//! plus lights behind the camera whose sphere reaches in front, lights straddling the near
//! plane and lights around the eye.

use crate::camera::Camera;
use crate::gpu_types::PointLight;
use crate::lights::{LightLayout, LightParams, RadiusRange};
use crate::material::{Material, NAMED_ALBEDOS};
use crate::mesh::MeshKind;
use crate::scene::{Object, Scene};
use glam::Vec3;
use rand::{Rng, SeedableRng};

/// The shapes random scenes draw from (a room would enclose its neighbours).
const SHAPES: [MeshKind; 5] = [MeshKind::Sphere, MeshKind::Teapot, MeshKind::TorusKnot, MeshKind::Plane, MeshKind::Disc];

/// A camera somewhere in the light box, looking at a random point near the ground; one in
/// four orthographic.
pub fn random_camera(rng: &mut impl Rng) -> Camera {
    let eye = Vec3::new(rng.random_range(-18.0..18.0), rng.random_range(0.5..14.0), rng.random_range(-18.0..18.0));
    let target = Vec3::new(rng.random_range(-10.0..10.0), rng.random_range(-2.0..2.0), rng.random_range(-10.0..10.0));
    let orthographic = rng.random_bool(0.25).then(|| rng.random_range(2.0..15.0));
    Camera { orthographic, ..Camera::looking_at(eye, target, rng.random_range(40.0..90.0), 0.1, 256.0) }
}

/// `count` random lights (radii 0.2–40) plus 12 placed against `camera`'s edge cases.
pub fn hostile_lights(rng: &mut impl Rng, camera: &Camera, count: u32) -> Vec<PointLight> {
    let params = LightParams { count, layout: LightLayout::Random, seed: rng.random(), radius: RadiusRange { min: 0.2, max: 40.0 } };
    let mut lights = params.build().expect("count is in range");
    let f = camera.forward();
    for i in 0..12 {
        let r = rng.random_range(0.3..6.0);
        let at = match i % 3 {
            0 => camera.position - f * (r * 0.7),   // centre behind the eye, sphere reaches in front
            1 => camera.position + f * camera.near, // straddling the near plane
            _ => camera.position + Vec3::new(rng.random_range(-0.2..0.2), 0.1, 0.0), // around the eye
        };
        let c = crate::lights::SEED_COLORS[i % 4];
        lights.push(PointLight { position_radius: [at.x, at.y, at.z, r], color: [c[0], c[1], c[2], 0.0] });
    }
    lights
}

/// The seed's 7×7 object grid with mixed meshes and materials, a random camera and
/// `1..=max_lights` hostile lights, all from `seed`.
pub fn random_scene(seed: u64, max_lights: u32) -> Scene {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let camera = random_camera(&mut rng);
    let count = rng.random_range(1..=max_lights.max(1));
    let lights = hostile_lights(&mut rng, &camera, count);
    let objects = (0..49)
        .map(|i| {
            let (_, albedo) = NAMED_ALBEDOS[rng.random_range(0..NAMED_ALBEDOS.len())];
            let at = |k: i32| (k as f32 - 3.5) * 2.5;
            let mesh = SHAPES[rng.random_range(0..SHAPES.len())];
            let material =
                Material { albedo: Vec3::from(albedo), roughness: rng.random_range(0.1..0.9), metallic: rng.random_range(0.0..1.0) };
            Object::placed(mesh, Vec3::new(at(i / 7), 0.0, at(i % 7)), 1.0, material)
        })
        .collect();
    Scene::new(objects, lights, camera)
}
