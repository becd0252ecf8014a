//! Determinism and frames in flight: the same arguments give the same bytes, and 100 frames
//! in a row (two in flight, animated lights) give no validation message.

use crate::common;

use ml_cpu::lights::LightParams;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::Scene;

fn seed_scene() -> Scene {
    Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap()
}

#[test]
fn rendering_twice_gives_identical_bytes() {
    let a = common::render(seed_scene(), common::settings(160, 90));
    let b = common::render(seed_scene(), common::settings(160, 90));
    assert_eq!(a.rgba.len(), 160 * 90 * 4);
    assert!(a.rgba == b.rgba, "two renders with the same arguments differ");
    // And the image is not trivially constant: the spheres and their highlights are there.
    let distinct: std::collections::HashSet<&[u8]> = a.rgba.chunks_exact(4).collect();
    assert!(distinct.len() > 100, "only {} distinct colours", distinct.len());
}

#[test]
fn hundred_animated_frames_with_two_in_flight_are_clean() {
    let mut settings = common::settings(96, 54);
    settings.frames = 100;
    settings.time = None; // animated: lights move every frame, uploads every frame
    let out = common::render(seed_scene(), settings);
    assert_eq!(out.stats.frames, 100);
    // Frame 99 is at t = 99/60 · 0.25; the last image must be that frame, not frame 0.
    let first = common::render(seed_scene(), common::settings(96, 54));
    assert!(out.rgba != first.rgba, "the animation did not move the lights");
    let mut at_last = common::settings(96, 54);
    at_last.time = Some(settings.clock(99));
    assert!(out.rgba == common::render(seed_scene(), at_last).rgba, "the read-back is not the last frame");
}
