//! Environment light against its CPU reference: a unit sphere lit by the built-in sky alone
//! (no point light reaches it), pbr model. For every pixel whose ray hits the analytic sphere,
//! the GPU pixel must lie within 2/255 of the split sum the CPU computes at that point
//! (ml_cpu::environment::environment_light: the coefficients and the GGX-weighted radiance
//! summed over every texel of the image, the BRDF integral with the table's 512 samples) — over the
//! range the reference takes with the normal tilted by the tessellation's error, as in the
//! point-light reference test. The GPU resamples the image into a cube, prefilters six
//! roughness levels by importance sampling and interpolates between them; the sky is smooth,
//! so each of those steps stays below a step of 8 bits. Every technique draws the same image.

use crate::common;

use glam::Vec3;
use ml_cpu::camera::Camera;
use ml_cpu::environment::{diffuse_sh9, environment_light, Environment, EnvironmentImage};
use ml_cpu::gpu_types::PointLight;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{Object, Scene};
use ml_cpu::shading::{aces_tone_map, encode_gamma_unorm8};
use ml_cpu::shading_model::ShadingModel;
use ml_render::{RenderSettings, Technique};
use std::sync::Arc;

const SIZE: u32 = 96;
const MAX_DIFF: u8 = 2;
const NORMAL_TOLERANCE: f32 = 2e-3;

fn sky_sphere(material: Material, rotation: f32) -> Scene {
    // One light far from the sphere, its radius ending before it: the environment alone lights it.
    let far = PointLight { position_radius: [50.0, 0.0, 0.0, 1.0], color: [1.0, 1.0, 1.0, 0.0] };
    let camera = Camera::looking_at(Vec3::new(0.3, 0.6, 3.2), Vec3::ZERO, 45.0, 0.1, 100.0);
    let mut scene = Scene::new(vec![Object::placed(MeshKind::Sphere, Vec3::ZERO, 1.0, material)], vec![far], camera);
    scene.environment = Some(Environment { image: Arc::new(EnvironmentImage::sky(128)), intensity: 1.3, rotation });
    scene
}

fn pbr(technique: Technique) -> RenderSettings {
    RenderSettings { shading: ShadingModel::Pbr, ..RenderSettings::new(technique, SIZE, SIZE) }
}

fn compare(material: Material, rotation: f32) {
    let scene = sky_sphere(material, rotation);
    let out = common::render(scene.clone(), pbr(Technique::Forward));
    let env = scene.environment.as_ref().expect("set above");
    let sh = diffuse_sh9(&env.image);
    let m = material;
    // Every other pixel, a checkerboard: the reference sums the whole image per point.
    let r = common::compare_sphere(&out, &scene.camera, true, (NORMAL_TOLERANCE, MAX_DIFF), |_, dir| {
        let sh = &sh;
        move |n: Vec3| encode_gamma_unorm8(aces_tone_map(environment_light(env, sh, (n, -dir), m.albedo, (m.roughness, m.metallic, 1.0))))
    });
    let (compared, outside) = (r.compared, r.outside);
    assert!(compared > 1_800, "the sphere should cover much of the image, got {compared} pixels");
    assert_eq!(outside, 0, "channels outside the reference range ± {MAX_DIFF}/255");
}

#[test]
fn environment_light_matches_the_cpu_split_sum_on_a_rough_metal() {
    compare(Material { albedo: Vec3::new(0.95, 0.75, 0.4), roughness: 0.45, metallic: 1.0 }, 0.0);
}

#[test]
fn environment_light_matches_the_cpu_split_sum_on_a_turned_sky() {
    compare(Material { albedo: Vec3::new(0.8, 0.3, 0.2), roughness: 0.7, metallic: 0.0 }, 2.0);
}

#[test]
fn every_technique_draws_the_same_environment_light() {
    let scene = sky_sphere(Material { albedo: Vec3::new(0.9, 0.9, 0.9), roughness: 0.3, metallic: 0.5 }, 1.0);
    let settings: Vec<RenderSettings> = Technique::ALL.iter().map(|&t| RenderSettings { width: 64, height: 64, ..pbr(t) }).collect();
    let outs = common::render_each(&scene, &settings);
    for (s, out) in settings.iter().zip(&outs).skip(1) {
        let (worst, differing) = common::max_difference(&outs[0], out);
        println!("{:?}: {differing} pixels differ, by up to {worst}/255", s.technique);
        assert!(worst <= 1, "{:?} differs from forward by {worst}/255", s.technique);
    }
}

/// The viewer turns and scales the environment in place (no new prefiltering): the image is
/// the one a renderer made for the turned, brighter environment draws.
#[test]
fn turning_the_environment_in_place_equals_a_renderer_made_turned() {
    use ml_vk::{Context, ContextDesc};
    use std::sync::atomic::Ordering;
    let scene = sky_sphere(Material { albedo: Vec3::new(0.9, 0.9, 0.9), roughness: 0.3, metallic: 0.5 }, 0.0);
    let mut turned = scene.clone();
    let env = turned.environment.as_mut().expect("set");
    (env.intensity, env.rotation) = (2.0, 1.0);
    let settings = RenderSettings { width: 64, height: 64, ..pbr(Technique::Visibility) };
    let ctx = Context::new(&ContextDesc { validation: true, ..Default::default() }).expect("a validated device");
    let counter = ctx.validation_counter();
    let made = ml_render::Renderer::new(&ctx, turned, settings).expect("renderer").render().expect("render");
    let mut renderer = ml_render::Renderer::new(&ctx, scene, settings).expect("renderer");
    let before = renderer.render().expect("render");
    assert!(renderer.set_environment_view(2.0, 1.0).expect("changed"));
    let after = renderer.render().expect("render");
    drop(renderer);
    drop(ctx);
    assert_eq!(counter.load(Ordering::SeqCst), 0, "validation messages (printed above)");
    assert!(common::max_difference(&before, &after).1 > 500, "the turn changed the image");
    assert_eq!(common::max_difference(&made, &after), (0, 0), "in place = made turned");
}
