//! glTF's PBR extensions (ml_cpu::material_lobes): each lobe on a unit sphere against the CPU
//! reference, as the point-light reference test compares the seed model (every pixel whose
//! ray hits the analytic sphere within 2/255 of the range the reference takes with the normal
//! tilted by the tessellation's error); each extension changes the image it is in; every
//! technique draws the same lobes, under point lights and the environment alike.

use crate::common;

use glam::Vec3;
use ml_cpu::camera::Camera;
use ml_cpu::environment::{Environment, EnvironmentImage};
use ml_cpu::gpu_types::PointLight;
use ml_cpu::lights::animate_into;
use ml_cpu::material::Material;
use ml_cpu::material_lobes::{shade_lobed, MaterialLobes};
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{Object, Scene};
use ml_cpu::shading::{aces_tone_map, encode_gamma_unorm8};
use ml_cpu::shading_model::ShadingModel;
use ml_render::{RenderSettings, Technique};
use std::sync::Arc;

const SIZE: u32 = 96;
const MAX_DIFF: u8 = 2;
const NORMAL_TOLERANCE: f32 = 2e-3;

fn light(p: [f32; 3], radius: f32, color: [f32; 3]) -> PointLight {
    PointLight { position_radius: [p[0], p[1], p[2], radius], color: [color[0], color[1], color[2], 0.0] }
}

fn lights() -> Vec<PointLight> {
    vec![
        light([2.0, 2.0, 2.0], 6.0, [3.0, 1.0, 0.6]),
        light([-2.5, 0.5, 1.5], 4.0, [0.4, 2.5, 0.8]),
        // Behind the sphere's rim as seen from the camera: grazing light, where sheen and the
        // coat's Fresnel show.
        light([0.8, -1.0, -2.0], 4.5, [1.0, 1.2, 3.0]),
    ]
}

fn pbr(technique: Technique, size: u32) -> RenderSettings {
    RenderSettings { shading: ShadingModel::Pbr, ..RenderSettings::new(technique, size, size) }
}

fn with_lobes(material: Material, lobes: MaterialLobes, at: Vec3, radius: f32) -> Object {
    let mut o = Object::placed(MeshKind::Sphere, at, radius, material);
    o.extras.lobes = lobes;
    o
}

fn rough_red() -> Material {
    Material { albedo: Vec3::new(0.7, 0.15, 0.1), roughness: 0.75, metallic: 0.0 }
}

fn clearcoat() -> MaterialLobes {
    MaterialLobes { clearcoat: 1.0, clearcoat_roughness: 0.15, ..Default::default() }
}

fn sheen() -> MaterialLobes {
    MaterialLobes { sheen_color: Vec3::new(0.9, 0.6, 1.0), sheen_roughness: 0.45, ..Default::default() }
}

fn specular() -> MaterialLobes {
    MaterialLobes { ior: 2.2, specular: 0.8, specular_color: Vec3::new(1.6, 0.6, 0.3), ..Default::default() }
}

fn compare(material: Material, lobes: MaterialLobes) {
    let camera = Camera::looking_at(Vec3::new(0.3, 0.6, 3.2), Vec3::ZERO, 45.0, 0.1, 100.0);
    let scene = Scene::new(vec![with_lobes(material, lobes, Vec3::ZERO, 1.0)], lights(), camera);
    let out = common::render(scene.clone(), pbr(Technique::Forward, SIZE));
    let mut lights = scene.lights.clone();
    animate_into(&scene.lights, 0.0, &mut lights);
    let (eye, ambient) = (scene.camera.position, scene.ambient);
    let r = common::compare_sphere(&out, &scene.camera, false, (NORMAL_TOLERANCE, MAX_DIFF), |p, _| {
        let lights = &lights;
        move |n: Vec3| encode_gamma_unorm8(aces_tone_map(shade_lobed(p, (n, n), eye, (&material, &lobes), lights, ambient, Vec3::ZERO)))
    });
    let (compared, outside) = (r.compared, r.outside);
    assert!(compared > 3_000, "the sphere should cover much of the image, got {compared} pixels");
    assert_eq!(outside, 0, "channels outside the reference range ± {MAX_DIFF}/255");
}

#[test]
fn a_clear_coat_matches_the_cpu_reference() {
    compare(rough_red(), clearcoat());
}

#[test]
fn sheen_matches_the_cpu_reference() {
    compare(rough_red(), sheen());
}

#[test]
fn ior_and_specular_match_the_cpu_reference() {
    compare(Material { roughness: 0.35, ..rough_red() }, specular());
}

/// Four spheres in a row, each with one extension (clear coat, sheen, ior and specular,
/// unlit), lit by point lights and the built-in sky.
fn four_lobes(lobes: [MaterialLobes; 4]) -> Scene {
    let objects =
        lobes.iter().enumerate().map(|(i, l)| with_lobes(rough_red(), *l, Vec3::new(i as f32 * 2.2 - 3.3, 0.0, 0.0), 1.0)).collect();
    let camera = Camera::looking_at(Vec3::new(0.0, 1.5, 7.5), Vec3::ZERO, 55.0, 0.1, 100.0);
    let mut scene = Scene::new(objects, lights(), camera);
    scene.sections.set(Some(Environment { image: Arc::new(EnvironmentImage::sky(64)), intensity: 0.8, rotation: 0.5, background: false }));
    scene
}

fn unlit() -> MaterialLobes {
    MaterialLobes { unlit: true, ..Default::default() }
}

#[test]
fn each_extension_changes_its_sphere_and_every_technique_draws_them_alike() {
    let size = 96;
    let lobes = [clearcoat(), sheen(), specular(), unlit()];
    let scene = four_lobes(lobes);
    let settings: Vec<RenderSettings> = Technique::ALL.iter().map(|&t| pbr(t, size)).collect();
    let outs = common::render_each(&scene, &settings);
    for (s, out) in settings.iter().zip(&outs).skip(1) {
        let (worst, differing) = common::max_difference(&outs[0], out);
        println!("{:?}: {differing} pixels differ, by up to {worst}/255", s.technique);
        assert!(worst <= 1, "{:?} differs from forward by {worst}/255", s.technique);
    }
    // The same spheres without their extensions: each sphere's pixels change (the spheres are
    // a quarter of the image wide each; count the pixels that differ in each quarter's band).
    let plain = common::render(four_lobes([MaterialLobes::default(); 4]), pbr(Technique::Forward, size));
    for (i, l) in lobes.iter().enumerate() {
        let columns = (i as u32 * size / 4)..((i as u32 + 1) * size / 4);
        let changed = columns
            .flat_map(|x| (0..size).map(move |y| (x, y)))
            .filter(|&(x, y)| common::pixel(&outs[0], x, y).iter().zip(common::pixel(&plain, x, y)).any(|(a, b)| a.abs_diff(b) > 3))
            .count();
        println!("{l:?}: {changed} pixels changed");
        assert!(changed > 150, "{l:?} changed only {changed} pixels of its sphere");
    }
}
