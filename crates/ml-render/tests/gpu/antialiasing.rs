//! Anti-aliasing (docs/DESIGN.md#anti-aliasing), the visibility technique's compute raster with
//! several coverage samples a pixel:
//! - against the same view supersampled 8×8 and filtered in linear light
//!   (`ml_cpu::supersample`), 8 samples cut the RMS error of the image without anti-aliasing
//!   to at most a third, on the bench scene and on foliage of alpha-masked leaves;
//! - it changes nothing it must not: culling off, and the light grid's marks on or off, give
//!   the same image byte for byte; two renders are byte-identical;
//! - a pixel shades each surface its samples hold once: a view filled by one quad shades a
//!   surface per pixel, and two where its diagonal splits the samples.
//!
//! Validation (with synchronization validation) stays silent.

use crate::common;

use glam::{Quat, Vec3};
use ml_cpu::camera::Camera;
use ml_cpu::gltf_writer::{cutout, png, quad, GltfWriter, PrimitiveData, CUTOUT_SIZE};
use ml_cpu::gpu_types::PointLight;
use ml_cpu::scene::Scene;
use ml_cpu::supersample::{downsample, rms_difference};
use ml_render::{Antialiasing, AntialiasingStats, Raster, RenderOutput, RenderSettings, ShadingModel, Technique};
use rand::{Rng, SeedableRng};
use serde_json::json;

/// The reference's supersampling, each axis.
const REFERENCE: u32 = 8;

/// The visibility technique with the compute raster at `width`×`height`, samples `aa`.
fn visibility(width: u32, height: u32, aa: Antialiasing) -> RenderSettings {
    RenderSettings {
        raster: Raster::compute(Raster::DEFAULT_SPLIT),
        antialiasing: aa,
        ..RenderSettings::new(Technique::Visibility, width, height)
    }
}

/// RMS error (8-bit units) of anti-aliasing off and at `samples` against the supersampled
/// reference of the same view.
fn errors(what: &str, scene: &Scene, base: RenderSettings, samples: Antialiasing) -> (f64, f64) {
    let (w, h) = (base.width, base.height);
    let big = RenderSettings { width: w * REFERENCE, height: h * REFERENCE, ..base };
    let settings = [big, base, RenderSettings { antialiasing: samples, ..base }];
    let Ok::<[RenderOutput; 3], _>([reference, off, aa]) = common::render_each(scene, &settings).try_into() else { panic!("three images") };
    let reference = downsample(&reference.rgba, (w * REFERENCE, h * REFERENCE), REFERENCE);
    let (e_off, e_aa) = (rms_difference(&off.rgba, &reference), rms_difference(&aa.rgba, &reference));
    println!("{what} {w}x{h}: RMS error against the {REFERENCE}x{REFERENCE} reference {e_off:.3} without anti-aliasing, {e_aa:.3} with {} samples ({:.2} of it)", samples.samples(), e_aa / e_off);
    (e_off, e_aa)
}

/// Foliage: 300 alpha-masked, double-sided leaves (the cut-out plate, small, turned every way)
/// in a bush over a floor, 128 lights.
fn foliage() -> Scene {
    let mut w = GltfWriter::new();
    let texture = w.texture(png(CUTOUT_SIZE, CUTOUT_SIZE, &cutout([255, 255, 255])), "image/png");
    let leaf = w.alpha_material(Some(texture), [0.25, 0.7, 0.2, 1.0], "MASK", None, true);
    let floor = w.material([0.5, 0.45, 0.4, 1.0], 0.0, 0.8);
    let floor_mesh = w.mesh(&[PrimitiveData { material: Some(floor), ..quad() }]);
    w.node(json!({ "mesh": floor_mesh, "scale": [6.0, 6.0, 6.0] }), true);
    let leaf_mesh = w.mesh(&[PrimitiveData { material: Some(leaf), ..quad() }]);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(52);
    for _ in 0..300 {
        let at = Vec3::new(rng.random_range(-1.5..1.5), rng.random_range(0.3..2.8), rng.random_range(-1.5..1.5));
        let turn =
            Quat::from_euler(glam::EulerRot::XYZ, rng.random_range(0.0..6.3), rng.random_range(0.0..6.3), rng.random_range(0.0..6.3));
        let scale = rng.random_range(0.12..0.3);
        w.node(
            json!({ "mesh": leaf_mesh, "translation": at.to_array(), "rotation": turn.to_array(), "scale": [scale, scale, scale] }),
            true,
        );
    }
    let (mut scene, _) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    scene.camera = Camera::looking_at(Vec3::new(0.5, 2.2, 5.5), Vec3::new(0.0, 1.5, 0.0), 45.0, 0.1, 50.0);
    scene.lights = (0..128)
        .map(|_| {
            let p = Vec3::new(rng.random_range(-3.0..3.0), rng.random_range(0.2..3.5), rng.random_range(-3.0..3.0));
            let c = [0; 3].map(|_| rng.random_range(0.3..1.0f32));
            PointLight { position_radius: [p.x, p.y, p.z, rng.random_range(1.0..3.0)], color: [c[0], c[1], c[2], 0.0] }
        })
        .collect();
    scene.cones.clear();
    scene.light_motion = 0.0;
    scene
}

#[test]
fn eight_samples_cut_the_error_against_the_supersampled_reference_to_a_third() {
    let bench = ml_cpu::bench_scene::bench_scene(1024, 1, 20).expect("the bench scene");
    let (off, aa) = errors("bench scene", &bench, visibility(320, 180, Antialiasing::Off), Antialiasing::X8);
    assert!(aa * 3.0 <= off, "bench scene: {aa:.3} with 8 samples against {off:.3} without");
    let leaves = foliage();
    let base = RenderSettings { shading: ShadingModel::Pbr, ..visibility(160, 120, Antialiasing::Off) };
    let (off, aa) = errors("foliage", &leaves, base, Antialiasing::X8);
    assert!(aa * 3.0 <= off, "foliage: {aa:.3} with 8 samples against {off:.3} without");
}

#[test]
fn samples_change_no_pixel_they_must_not() {
    // The marks' pass runs where the settings leave it on (their default).
    let scene = ml_cpu::bench_scene::bench_scene(4096, 3, 12).expect("the bench scene");
    let base = visibility(160, 96, Antialiasing::X8);
    assert!(base.light_grid_marks);
    let settings = [base, base, RenderSettings { culling: false, ..base }, RenderSettings { light_grid_marks: false, ..base }];
    let outputs = common::render_each(&scene, &settings);
    for (what, out) in ["a second render", "culling off", "the light grid's marks off"].iter().zip(&outputs[1..]) {
        let (worst, pixels) = common::max_difference(&outputs[0], out);
        assert_eq!((worst, pixels), (0, 0), "{what}: {pixels} pixels differ, by up to {worst}/255");
    }
    let leaves = foliage();
    let base = visibility(128, 96, Antialiasing::X8);
    let outputs = common::render_each(&leaves, &[base, RenderSettings { culling: false, ..base }]);
    assert_eq!(common::max_difference(&outputs[0], &outputs[1]), (0, 0), "foliage: culling off changed the image");
}

#[test]
fn a_pixel_shades_each_surface_its_samples_hold_once() {
    // One quad filling the view: two triangles, their shared diagonal across the image.
    let mut w = GltfWriter::new();
    let m = w.material([0.7, 0.7, 0.7, 1.0], 0.0, 0.5);
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(
        json!({ "mesh": mesh, "rotation": Quat::from_rotation_x(std::f32::consts::FRAC_PI_2).to_array(), "scale": [8.0, 8.0, 8.0] }),
        true,
    );
    let (mut scene, _) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    scene.camera = Camera::looking_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 60.0, 0.1, 20.0);
    scene.lights = vec![PointLight { position_radius: [0.0, 0.0, 2.0, 10.0], color: [1.0, 1.0, 1.0, 0.0] }];
    let (width, height) = (64, 48);
    for aa in [Antialiasing::X4, Antialiasing::X8, Antialiasing::X16] {
        let out = common::render(scene.clone(), visibility(width, height, aa));
        let stats = out.stats.feature::<AntialiasingStats>().expect("anti-aliasing reports its samples");
        let pixels = u64::from(width * height);
        // The diagonal crosses at most width + height pixels, each shading both triangles.
        let diagonal = u64::from(width + height);
        println!("{} samples: {} surfaces shaded over {pixels} pixels", aa.samples(), stats.surfaces);
        assert!(stats.surfaces > pixels && stats.surfaces <= pixels + diagonal, "{} samples: {} surfaces", aa.samples(), stats.surfaces);
    }
}
