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
use crate::common::view;

use glam::Vec3;
use ml_cpu::camera::Camera;
use ml_cpu::environment::{diffuse_sh9, environment_light, Environment, EnvironmentImage};
use ml_cpu::gpu_types::PointLight;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{Object, Scene};
use ml_cpu::shading::{aces_tone_map, encode_gamma_unorm8};
use ml_cpu::shading_model::ShadingModel;
use ml_render::{EnvironmentView, RenderSettings, Technique};
use std::sync::Arc;

const SIZE: u32 = 96;
const MAX_DIFF: u8 = 2;
const NORMAL_TOLERANCE: f32 = 2e-3;

fn sky_sphere(material: Material, rotation: f32) -> Scene {
    // One light far from the sphere, its radius ending before it: the environment alone lights it.
    let far = PointLight { position_radius: [50.0, 0.0, 0.0, 1.0], color: [1.0, 1.0, 1.0, 0.0] };
    let camera = Camera::looking_at(Vec3::new(0.3, 0.6, 3.2), Vec3::ZERO, 45.0, 0.1, 100.0);
    let mut scene = Scene::new(vec![Object::placed(MeshKind::Sphere, Vec3::ZERO, 1.0, material)], vec![far], camera);
    scene.sections.set(Some(Environment { image: Arc::new(EnvironmentImage::sky(128)), intensity: 1.3, rotation, background: false }));
    scene
}

fn pbr(technique: Technique) -> RenderSettings {
    RenderSettings { shading: ShadingModel::Pbr, ..RenderSettings::new(technique, SIZE, SIZE) }
}

fn compare(material: Material, rotation: f32) {
    let scene = sky_sphere(material, rotation);
    let out = common::render(scene.clone(), pbr(Technique::Forward));
    let env = scene.sections.get::<Environment>().expect("set above");
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
    let scene = sky_sphere(Material { albedo: Vec3::new(0.9, 0.9, 0.9), roughness: 0.3, metallic: 0.5 }, 0.0);
    let mut turned = scene.clone();
    let env = turned.sections.get_mut::<Environment>().expect("set");
    (env.intensity, env.rotation) = (2.0, 1.0);
    let settings = RenderSettings { width: 64, height: 64, ..pbr(Technique::Visibility) };
    let ctx = common::pooled_context();
    let made = ml_render::Renderer::new(&ctx, turned, settings).expect("renderer").render().expect("render");
    let mut renderer = ml_render::Renderer::new(&ctx, scene, settings).expect("renderer");
    let before = renderer.render().expect("render");
    assert!(renderer.set_environment_view(2.0, 1.0).expect("changed"));
    let after = renderer.render().expect("render");
    drop(renderer);
    drop(ctx);
    assert!(common::max_difference(&before, &after).1 > 500, "the turn changed the image");
    assert_eq!(common::max_difference(&made, &after), (0, 0), "in place = made turned");
}

/// A background pixel and the range of colours the CPU sees over it (lowest, highest).
type Seen = ((u32, u32), ([u8; 3], [u8; 3]));

/// `--background environment`: where no surface is, each pixel shows the sky along its ray,
/// exposed and tone-mapped as the surfaces are — within 2/255 of what the CPU's bilinear read
/// of the image gives over the pixel (the GPU reads its cube) — in every technique, with anti-aliasing and with
/// transparent layers (their resolves lay it too); debug views keep the colour.
#[test]
fn the_background_shows_the_environment_along_each_pixels_ray() {
    use ml_render::{Antialiasing, Background};
    let mut scene = sky_sphere(Material { albedo: Vec3::new(0.9, 0.9, 0.9), roughness: 0.3, metallic: 0.5 }, 1.0);
    // Its cube (256 texels a face) finer than the pixels (a texel 0.35°, a pixel 0.5°).
    scene.sections.get_mut::<Environment>().expect("set above").image = Arc::new(EnvironmentImage::sky(1024));
    let env = scene.sections.get::<Environment>().expect("set above");
    let seen = |s: RenderSettings| RenderSettings { background: Background::Environment, ..s };
    let mut settings: Vec<RenderSettings> = Technique::ALL.iter().map(|&t| seen(pbr(t))).collect();
    for t in [Technique::Forward, Technique::Deferred, Technique::Visibility] {
        settings.push(RenderSettings { antialiasing: Antialiasing::X4, ..seen(pbr(t)) });
    }
    let plain = Technique::ALL.len() + 3;
    settings.push(pbr(Technique::Forward));
    settings.push(RenderSettings { debug_view: view("depth"), ..seen(pbr(Technique::Visibility)) });
    let outs = common::render_each(&scene, &settings);
    // Pixels whose ray passes the sphere (radius 1) by a margin: the background.
    // Per background pixel, the range of what the CPU sees over the pixel (its centre and
    // corners): the GPU resamples the image into its cube and reads that, which may move the
    // horizon's steep gradient by a fraction of a pixel.
    let mut background = Vec::new();
    for (x, y) in (0..SIZE).flat_map(|y| (0..SIZE).map(move |x| (x, y))) {
        let seen_at = |dx: f32, dy: f32| {
            let (o, d) = common::shadow_rays::ray(&scene.camera, x as f32 + 0.5 + dx, y as f32 + 0.5 + dy, SIZE);
            ((o - d * o.dot(d)).length(), encode_gamma_unorm8(aces_tone_map(env.image.radiance(env.to_image() * d) * env.intensity)))
        };
        let seen: Vec<(f32, [u8; 3])> =
            [(0.0, 0.0), (-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)].map(|(dx, dy)| seen_at(dx, dy)).to_vec();
        if seen.iter().all(|&(closest, _)| closest > 1.05) {
            let lo: [u8; 3] = std::array::from_fn(|c| seen.iter().map(|s| s.1[c]).min().unwrap());
            let hi: [u8; 3] = std::array::from_fn(|c| seen.iter().map(|s| s.1[c]).max().unwrap());
            background.push(((x, y), (lo, hi)));
        }
    }
    assert!(background.len() > 4_000, "{} background pixels", background.len());
    // How far beyond its range each pixel lies, at worst.
    let worst = |out: &ml_render::RenderOutput| {
        let beyond = |&((x, y), (lo, hi)): &Seen| {
            let p = common::pixel(out, x, y);
            (0..3).map(|c| lo[c].saturating_sub(p[c]).max(p[c].saturating_sub(hi[c]))).max().unwrap()
        };
        background.iter().map(beyond).max()
    };
    let forward = &outs[0];
    println!("forward: the background within {:?}/255 of the CPU's", worst(forward));
    assert!(worst(forward).unwrap() <= MAX_DIFF, "forward's background is not the sky");
    for (s, out) in settings.iter().zip(&outs).take(plain).skip(1) {
        let (most, differing) = common::max_difference(forward, out);
        println!("{:?} at {:?}: {differing} pixels differ from forward, by up to {most}/255", s.technique, s.antialiasing);
        assert!(worst(out).unwrap() <= MAX_DIFF, "{:?} at {:?}: the background is not the sky", s.technique, s.antialiasing);
        // Anti-aliasing changes the sphere's edge, not the background.
        if s.antialiasing == Antialiasing::Off {
            assert!(most <= 1, "{:?} differs from forward by {most}/255", s.technique);
        }
    }
    // The sphere made transparent: the transparent layers' resolve lays the background (the
    // layers blended over it, through the sphere).
    let mut glass = scene.clone();
    (glass.objects[0].extras.alpha_mode, glass.objects[0].extras.base_alpha) = (ml_cpu::scene::AlphaMode::Blend, 0.5);
    let layers = |s: RenderSettings| RenderSettings { transparency: Some(Default::default()), ..s };
    let mut through: Vec<RenderSettings> =
        [Technique::Forward, Technique::Deferred, Technique::DeferredCompute, Technique::Visibility].map(|t| layers(seen(pbr(t)))).to_vec();
    // (Layers over samples: the visibility technique's.)
    through.push(RenderSettings { antialiasing: Antialiasing::X4, ..layers(seen(pbr(Technique::Visibility))) });
    for (s, out) in through.iter().zip(common::render_each(&glass, &through)) {
        println!("{:?} at {:?} through layers: the background within {:?}/255", s.technique, s.antialiasing, worst(&out));
        assert!(worst(&out).unwrap() <= MAX_DIFF, "{:?} at {:?} with layers: the background is not the sky", s.technique, s.antialiasing);
    }
    // The colour background, and a debug view, keep the dark grey.
    for out in &outs[plain..] {
        assert!(background.iter().all(|&((x, y), _)| common::pixel(out, x, y) == [5, 5, 5]), "the colour background");
    }
}
