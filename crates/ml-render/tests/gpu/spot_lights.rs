//! Spot lights (glTF KHR_lights_punctual, from a file our writer makes): a spot straight above
//! a floor, inner
//! cone 20°, outer 30°. Inside the inner cone the floor is exactly as the same light without
//! a cone lights it, outside the outer cone exactly as with no light, and in between it fades
//! (glTF's smooth edge) — each where the CPU puts the cone's edge on the floor. Every technique
//! draws the same image.

use crate::common;

use glam::Vec3;
use ml_cpu::camera::Camera;
use ml_cpu::scene::Scene;
use ml_render::{RenderOutput, RenderSettings, ShadingModel, Technique};

const SIZE: u32 = 128;
const HEIGHT: f32 = 3.0;
const INNER_DEG: f32 = 20.0;
const OUTER_DEG: f32 = 30.0;

/// The floor, the camera and one light, as a glTF file made by our writer: a spot straight
/// down (its node turned a quarter about −X), the same light as a point light, or dark.
fn scene(kind: &str, on: bool) -> Scene {
    use ml_cpu::gltf_writer::{quad, GltfWriter, PrimitiveData};
    use serde_json::json;
    let mut w = GltfWriter::new();
    let floor = w.material([0.8, 0.8, 0.8, 1.0], 0.0, 0.9);
    let mesh = w.mesh(&[PrimitiveData { material: Some(floor), ..quad() }]);
    w.node(json!({ "mesh": mesh, "scale": [4.0, 1.0, 4.0] }), true);
    let mut light = json!({ "type": kind, "intensity": if on { 2.0 } else { 0.0 }, "range": 20.0 });
    if kind == "spot" {
        light["spot"] = json!({ "innerConeAngle": INNER_DEG.to_radians(), "outerConeAngle": OUTER_DEG.to_radians() });
    }
    let light = w.light(light);
    let half = std::f32::consts::FRAC_1_SQRT_2;
    w.node(json!({ "translation": [0.0, HEIGHT, 0.0], "rotation": [-half, 0.0, 0.0, half], "extensions": { "KHR_lights_punctual": { "light": light } } }), true);
    let (mut scene, warnings) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    assert!(warnings.is_empty(), "{warnings:?}");
    scene.camera = Camera::looking_at(Vec3::new(0.0, 6.0, 0.01), Vec3::ZERO, 70.0, 0.1, 50.0);
    scene
}

fn settings(technique: Technique) -> RenderSettings {
    let mut s = RenderSettings::new(technique, SIZE, SIZE);
    s.shading = ShadingModel::Pbr;
    s
}

/// Angle from the spot's axis at the floor point a pixel sees (None: off the floor). The
/// renderer moves lights by the seed's animation (at time 0: +0.1 in z).
fn angle_at(camera: &Camera, x: u32, y: u32) -> Option<f32> {
    let (o, d) = camera.pixel_ray(x, y, SIZE, SIZE);
    let p = o + d * (-o.y / d.y) - ml_cpu::lights::animation_offset(0.0);
    (p.x.abs() < 3.9 && p.z.abs() < 3.9).then(|| (p.x.hypot(p.z) / HEIGHT).atan().to_degrees())
}

#[test]
fn a_spot_lights_its_cone_and_nothing_outside() {
    let shaded = |kind, on| common::render(scene(kind, on), settings(Technique::Forward));
    let (spot_image, open, dark): (RenderOutput, RenderOutput, RenderOutput) =
        (shaded("spot", true), shaded("point", true), shaded("point", false));
    let camera = scene("point", true).camera;
    let (mut inside, mut outside, mut between) = (0, 0, 0);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let Some(angle) = angle_at(&camera, x, y) else { continue };
            let (s, o, d) = (common::pixel(&spot_image, x, y), common::pixel(&open, x, y), common::pixel(&dark, x, y));
            // A pixel spans about 0.4° here: half a degree either side of an edge is left out.
            if angle < INNER_DEG - 0.5 {
                assert_eq!(s, o, "inside the inner cone at {angle:.2}° (pixel {x}, {y})");
                inside += 1;
            } else if angle > OUTER_DEG + 0.5 {
                assert_eq!(s, d, "outside the outer cone at {angle:.2}° (pixel {x}, {y})");
                outside += 1;
            } else if angle > INNER_DEG + 2.0 && angle < OUTER_DEG - 2.0 {
                let sum = |p: [u8; 3]| p.iter().map(|&c| c as u32).sum::<u32>();
                assert!(sum(d) < sum(s) && sum(s) < sum(o), "the edge at {angle:.2}° should fade: {s:?} between {d:?} and {o:?}");
                between += 1;
            }
        }
    }
    println!("{inside} pixels inside, {between} fading, {outside} outside");
    assert!(inside > 500 && between > 300 && outside > 1000);
}

#[test]
fn every_technique_draws_the_same_spot() {
    let all: Vec<RenderSettings> = Technique::ALL.iter().map(|&t| settings(t)).collect();
    let outputs = common::render_each(&scene("spot", true), &all);
    for (t, out) in Technique::ALL.iter().zip(&outputs).skip(1) {
        let (max, _) = common::max_difference(&outputs[0], out);
        assert!(max <= 1, "{} differs from forward by {max}/255", t.name());
    }
}
