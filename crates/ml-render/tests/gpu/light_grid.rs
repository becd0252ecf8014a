//! The light grid (the GPU techniques' light assignment): a million lights at 160×90 against
//! brute force on the CPU over every light, on a crop, with the marks and without; a hundred
//! thousand lights without a validation message; and lights whose cluster lists outgrow a
//! storage buffer, which the light grid (one entry per light) still renders.

use crate::common;

use glam::Vec3;
use ml_cpu::camera::Camera;
use ml_cpu::gpu_types::PointLight;
use ml_cpu::lights::{LightLayout, LightParams, RadiusRange};
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{Object, Scene};
use ml_cpu::shading::{encode_gamma_unorm8, shade_seed};
use ml_render::{LightGridStats, Raster, RenderError, RenderSettings, Renderer, Technique};
use ml_vk::{Context, ContextDesc};
use std::sync::atomic::Ordering;

const W: u32 = 160;
const H: u32 = 90;
/// Allowed difference from the CPU, in 8-bit steps: float sums in another order, the GPU's
/// interpolated position on the wall, UNORM rounding.
const MAX_DIFF: u8 = 2;

/// A wall at z = 0 facing a camera at z = 4, and `count` lights uniform in the slab
/// |z| ≤ 1 in front of and behind it, of the radius that brings about four to a point.
fn wall_under(count: usize) -> Scene {
    let rotation = glam::Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let material = Material { albedo: Vec3::splat(0.8), roughness: 0.9, metallic: 0.2 };
    let mut wall = Object::placed(MeshKind::Plane, Vec3::ZERO, 1.0, material);
    wall.transform = glam::Mat4::from_scale_rotation_translation(Vec3::new(20.0, 1.0, 20.0), rotation, Vec3::ZERO);
    let (lo, hi) = (Vec3::new(-5.0, -3.0, -1.0), Vec3::new(5.0, 3.0, 1.0));
    let volume = (hi - lo).element_product();
    let radius = (4.0 * volume / (count as f32 * 4.0 / 3.0 * std::f32::consts::PI)).cbrt();
    let mut state = 0x9e3779b97f4a7c15u64;
    let mut next = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let lights = (0..count)
        .map(|_| {
            let p = lo + Vec3::new(next(), next(), next()) * (hi - lo);
            PointLight {
                position_radius: [p.x, p.y, p.z, radius],
                color: [2.0 + 6.0 * next(), 2.0 + 6.0 * next(), 2.0 + 6.0 * next(), 0.0],
            }
        })
        .collect();
    let camera = Camera::looking_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 60.0, 0.1, 30.0);
    let mut s = Scene::new(vec![wall], lights, camera);
    s.light_motion = 0.0;
    s
}

#[test]
fn a_million_lights_equal_brute_force_on_a_crop() {
    let scene = wall_under(1 << 20);
    let ctx = Context::new(&ContextDesc { validation: true, ..Default::default() }).expect("a Vulkan device with validation");
    let counter = ctx.validation_counter();
    let material = scene.objects[0].material;
    // The crop: 12×8 pixels around the image's centre.
    let crop: Vec<(u32, u32)> = (0..8).flat_map(|y| (0..12).map(move |x| (W / 2 - 6 + x, H / 2 - 4 + y))).collect();
    let reference: Vec<[u8; 3]> = crop
        .iter()
        .map(|&(x, y)| {
            let (o, d) = scene.camera.pixel_ray(x, y, W, H);
            let p = o + d * (-o.z / d.z);
            encode_gamma_unorm8(shade_seed(p, Vec3::Z, scene.camera.position, &material, &scene.lights, scene.ambient))
        })
        .collect();
    let lit = reference.iter().filter(|c| c.iter().any(|&v| v > 50)).count();
    assert!(lit > crop.len() / 5, "a crop the lights light: {lit} of {} pixels", crop.len());
    // (technique, raster, whether the surfaces mark the cells they walk first)
    let compute = Raster::compute(Raster::DEFAULT_SPLIT);
    let variants = [
        (Technique::ClusteredGpu, Raster::Hardware, false),
        (Technique::DeferredCompute, Raster::Hardware, true),
        (Technique::Visibility, compute, true),
        (Technique::DeferredCompute, Raster::Hardware, false),
        (Technique::Visibility, compute, false),
    ];
    for (technique, raster, marks) in variants {
        let settings = RenderSettings { raster, light_grid_marks: marks, ..RenderSettings::new(technique, W, H) };
        let out = Renderer::new(&ctx, scene.clone(), settings).and_then(|mut r| r.render()).expect("render");
        let grid = out.stats.feature::<LightGridStats>().expect("the light grid's figures");
        if !marks {
            // No marks (no surfaces before its lighting, or not asked for): every cell
            // marked, every light listed once.
            assert_eq!((grid.listed, grid.cells_marked), (1 << 20, grid.dims.iter().product()), "every light listed once");
        } else {
            // The marks: only the cells the wall's points walk, a few layers of the box.
            assert!(grid.listed < (1 << 20) / 4, "{}: the lights far from the wall are left out: {grid:?}", technique.name());
        }
        let mut worst = 0;
        for (&(x, y), want) in crop.iter().zip(&reference) {
            let got = common::pixel(&out, x, y);
            let diff = (0..3).map(|c| got[c].abs_diff(want[c])).max().unwrap_or(0);
            worst = worst.max(diff);
            assert!(diff <= MAX_DIFF, "{} (marks {marks}): pixel ({x}, {y}) is {got:?}, brute force {want:?}", technique.name());
        }
        println!("{} (marks {marks}): {grid:?}; crop within {worst}/255 of brute force", technique.name());
    }
    drop(ctx);
    assert_eq!(counter.load(Ordering::SeqCst), 0, "validation messages (printed above)");
}

#[test]
fn a_hundred_thousand_lights_render_cleanly() {
    let lights = LightParams { count: 100_000, layout: LightLayout::Random, seed: 7, radius: RadiusRange { min: 0.5, max: 1.5 } };
    let scene = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &lights).unwrap();
    let out = common::render(scene, RenderSettings::new(Technique::ClusteredGpu, 320, 180));
    let grid = out.stats.feature::<LightGridStats>().expect("the light grid's figures");
    println!("100k lights: {grid:?}");
    assert_eq!(grid.listed, 100_000);
    assert!(grid.max_per_cell < 1000, "the lights spread over many cells");
}

#[test]
fn lists_larger_than_a_storage_buffer_fail_loudly_where_the_light_grid_renders() {
    // 1,000 lights of radius 40 on a fine cluster grid need ~240 MiB of cluster lists: more
    // than lavapipe binds (128 MiB). clustered-cpu must say so, not render short lists; the
    // light grid lists each light once and renders.
    let lights = LightParams { count: 1000, layout: LightLayout::Random, seed: 3, radius: RadiusRange::fixed(40.0) };
    let scene = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &lights).unwrap();
    let ctx = Context::new(&ContextDesc { validation: true, ..Default::default() }).expect("Vulkan with validation");
    let counter = ctx.validation_counter();
    let limit = ctx.info.limits.max_storage_buffer_range as u64;
    let fine = ml_cpu::cluster::ClusterDims { x: 64, y: 36, z: 32 };
    let settings = RenderSettings { clusters: fine, ..RenderSettings::new(Technique::ClusteredCpu, 64, 36) };
    match Renderer::new(&ctx, scene.clone(), settings).and_then(|mut r| r.render()) {
        Err(e) => {
            let text = e.to_string();
            assert!(matches!(e, RenderError::ListsTooLong(_)), "{text}");
            assert!(text.contains("light lists need") && text.contains("coarser cluster grid"), "{text}");
        }
        Ok(out) => {
            // Only a device that binds enough may succeed, and then with every entry.
            let c = out.stats.clusters.expect("stats");
            assert!(c.index_len as u64 * 4 <= limit, "{} entries rendered past the limit", c.index_len);
        }
    }
    let settings = RenderSettings { clusters: fine, ..RenderSettings::new(Technique::ClusteredGpu, 64, 36) };
    let out = Renderer::new(&ctx, scene, settings).and_then(|mut r| r.render()).expect("the light grid renders");
    assert_eq!(out.stats.feature::<LightGridStats>().expect("its figures").listed, 1000);
    drop(ctx);
    assert_eq!(counter.load(Ordering::SeqCst), 0, "validation messages");
}

#[test]
fn lights_that_reach_only_a_transparent_layer_are_listed() {
    // A wall at z = 0 and a glass pane at z = 1.5 in front of it, each lit by its own light:
    // the pane's is 1.7 from the wall with a radius of 0.6, so the wall's points walk no cell of
    // it; only the marks of the pane's nodes keep it in the lists.
    let rotation = glam::Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let pane = |z: f32, half: f32, albedo: f32| {
        let material = Material { albedo: Vec3::splat(albedo), roughness: 0.7, metallic: 0.0 };
        let mut o = Object::placed(MeshKind::Plane, Vec3::ZERO, 1.0, material);
        o.transform = glam::Mat4::from_scale_rotation_translation(Vec3::new(half, 1.0, half), rotation, Vec3::new(0.0, 0.0, z));
        o
    };
    let mut glass = pane(1.5, 1.0, 0.9);
    glass.extras.alpha_mode = ml_cpu::scene::AlphaMode::Blend;
    glass.extras.base_alpha = 0.5;
    let light = |z: f32, c: f32| PointLight { position_radius: [0.1, 0.05, z, 0.6], color: [c, c, c, 0.0] };
    let camera = Camera::looking_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 50.0, 0.1, 20.0);
    let mut scene = Scene::new(vec![pane(0.0, 6.0, 0.8), glass], vec![light(0.4, 3.0), light(1.7, 20.0)], camera);
    scene.light_motion = 0.0;
    let settings = |technique| {
        let mut s = RenderSettings { transparency: Some(Default::default()), ..RenderSettings::new(technique, W, H) };
        if technique == Technique::Visibility {
            s.raster = Raster::compute(Raster::DEFAULT_SPLIT);
        }
        s
    };
    let outs =
        common::render_each(&scene, &[settings(Technique::Forward), settings(Technique::DeferredCompute), settings(Technique::Visibility)]);
    let lit_by_the_pane_light = {
        let unlit = Scene::new(scene.objects.clone(), vec![light(0.4, 3.0)], scene.camera);
        common::max_difference(&outs[0], &common::render(unlit, settings(Technique::Forward)))
    };
    assert!(lit_by_the_pane_light.0 > 20 && lit_by_the_pane_light.1 > 100, "the pane's light shows on the pane: {lit_by_the_pane_light:?}");
    for (out, name) in outs[1..].iter().zip(["deferred-compute", "visibility"]) {
        let grid = out.stats.feature::<LightGridStats>().expect("the light grid's figures");
        assert_eq!(grid.listed, 2, "{name}: both lights listed: {grid:?}");
        let (worst, count) = common::max_difference(&outs[0], out);
        assert!(worst <= 1, "{name}: {count} pixels differ from forward, by up to {worst}");
    }
}
