//! The benchmark scene (`--scene bench`, docs/scenes.md#bench): a large floor with a few hundred objects of
//! mixed kinds and sizes (more on request, spread over the same floor: denser, not wider), and N lights spread uniformly through the random-layout box with a
//! radius that shrinks as N^(−1/3), so that a point is reached by about the same number of
//! lights at every N: cost against N then shows the algorithm, not the light density.

use crate::camera::Camera;
pub use crate::lights::LIGHTS_PER_POINT;
use crate::lights::{LightFrame, LightLayout, LightParams, RadiusRange, RANDOM_BOX_MAX, RANDOM_BOX_MIN};
use crate::limits::MAX_BENCH_OBJECTS;
use crate::material::{Material, NAMED_ALBEDOS};
use crate::mesh::MeshKind;
use crate::scene::{Object, Scene};
use crate::SceneError;
use glam::{Mat4, Quat, Vec3};
use rand::{Rng, SeedableRng};

/// Objects on the floor besides the floor itself, unless asked otherwise.
pub const BENCH_OBJECTS: usize = 300;
/// The radius at which `count` lights uniform in the light box reach LIGHTS_PER_POINT lights
/// at an average point: count · (4/3)πr³ / V = LIGHTS_PER_POINT (the random layout's default
/// radius in the built-in frame).
pub fn bench_radius(count: u32) -> f32 {
    LightFrame::BUILT_IN.default_radius(LightLayout::Random, count, 0.0)
}

/// The scene with `count` lights (placed from `seed`) and `objects` objects. The objects never
/// change with the lights, and the first n of any count are the same: more objects add to
/// the scene, they do not move what was there.
pub fn bench_scene(count: u32, seed: u64, objects: usize) -> Result<Scene, SceneError> {
    if objects > MAX_BENCH_OBJECTS {
        return Err(SceneError::ObjectCount(objects));
    }
    let r = bench_radius(count);
    let lights = LightParams { count, layout: LightLayout::Random, seed, radius: RadiusRange { min: r, max: r } }.build()?;
    let floor_y = RANDOM_BOX_MIN.y;
    let half = (RANDOM_BOX_MAX.x - RANDOM_BOX_MIN.x) * 0.55;
    let floor = Material { albedo: Vec3::splat(0.6), roughness: 0.8, metallic: 0.0 };
    let mut placed = vec![Object {
        transform: Mat4::from_scale_rotation_translation(Vec3::splat(half), Quat::IDENTITY, Vec3::new(0.0, floor_y, 0.0)),
        ..Object::placed(MeshKind::Plane, Vec3::ZERO, 1.0, floor)
    }];
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0xbe7c);
    let kinds = [MeshKind::Sphere, MeshKind::Teapot, MeshKind::TorusKnot, MeshKind::Cube];
    for _ in 0..objects {
        let kind = kinds[rng.random_range(0..kinds.len())];
        let scale = rng.random_range(0.3f32..2.0);
        let (_, albedo) = NAMED_ALBEDOS[rng.random_range(0..7)];
        let material = Material { albedo: Vec3::from(albedo), roughness: rng.random_range(0.2..0.8), metallic: rng.random_range(0.0..1.0) };
        let at = Vec3::new(
            rng.random_range(RANDOM_BOX_MIN.x..RANDOM_BOX_MAX.x),
            floor_y + scale,
            rng.random_range(RANDOM_BOX_MIN.z..RANDOM_BOX_MAX.z),
        );
        let turn = Quat::from_rotation_y(rng.random_range(0.0..std::f32::consts::TAU));
        placed.push(Object {
            transform: Mat4::from_scale_rotation_translation(Vec3::splat(scale), turn, at),
            ..Object::placed(kind, Vec3::ZERO, 1.0, material)
        });
    }
    let camera = Camera::looking_at(Vec3::new(-26.0, 16.0, -26.0), Vec3::new(0.0, floor_y, 0.0), 60.0, 0.1, 200.0);
    Ok(Scene::new(placed, lights, camera))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lights_per_point_stay_constant_as_the_count_grows() {
        // Monte Carlo over random points of the box: lights whose sphere holds the point.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let inner = (RANDOM_BOX_MIN + 3.0, RANDOM_BOX_MAX - 3.0);
        for count in [1_000, 16_000, 64_000] {
            let scene = bench_scene(count, 1, BENCH_OBJECTS).unwrap();
            assert_eq!(scene.objects.len(), BENCH_OBJECTS + 1);
            let points: Vec<Vec3> = (0..200)
                .map(|_| {
                    Vec3::new(
                        rng.random_range(inner.0.x..inner.1.x),
                        rng.random_range(inner.0.y..inner.1.y),
                        rng.random_range(inner.0.z..inner.1.z),
                    )
                })
                .collect();
            let reached: usize = points
                .iter()
                .map(|p| {
                    scene.lights.iter().filter(|l| Vec3::from_slice(&l.position_radius[..3]).distance(*p) < l.position_radius[3]).count()
                })
                .sum();
            let mean = reached as f32 / points.len() as f32;
            assert!((mean - LIGHTS_PER_POINT).abs() < 1.0, "{count} lights: {mean} per point");
        }
        assert!((bench_radius(8_000) * 2.0 - bench_radius(1_000)).abs() < 1e-3);
    }

    #[test]
    fn more_objects_add_to_the_same_floor() {
        let (few, many) = (bench_scene(100, 1, BENCH_OBJECTS).unwrap(), bench_scene(100, 1, 10 * BENCH_OBJECTS).unwrap());
        assert_eq!(many.objects.len(), 10 * BENCH_OBJECTS + 1);
        assert_eq!(few.objects[..], many.objects[..few.objects.len()], "the first objects stay where they were");
        // Same spread: every object's position inside the floor's square.
        let floor = many.objects[0].transform.to_scale_rotation_translation();
        for o in &many.objects[1..] {
            let at = o.transform.w_axis.truncate();
            assert!((at.x - floor.2.x).abs() <= floor.0.x && (at.z - floor.2.z).abs() <= floor.0.z);
        }
        assert_eq!(bench_scene(100, 1, 0).unwrap().objects.len(), 1);
        assert_eq!(bench_scene(100, 1, MAX_BENCH_OBJECTS + 1), Err(SceneError::ObjectCount(MAX_BENCH_OBJECTS + 1)));
    }
}
