//! Golden images: every technique on the seed, room, bench and random scenes (and the
//! blinn-phong and pbr models, point-light shadows, a textured glTF scene and the debug views),
//! compared with PNGs kept in `tests/golden/<driver>/`, a set per driver (lavapipe's, which
//! CI runs, and NVIDIA's). Restructuring the renderer must not move a pixel beyond rounding;
//! a change that means to change images re-blesses them on purpose, on each driver:
//!
//! ```sh
//! MANYLIGHTS_BLESS=1 cargo test -p ml-render --test gpu golden::
//! ```
//!
//! A committed image was made on one machine, and the same driver rounds differently on
//! another: lavapipe's shaders follow the CPU's vector width and instruction set, so a few
//! pixels land a step apart (measured: 8 pixels of one image by 1/255 between two AVX-512
//! machines; none between 256 and 128 bits on one). The comparison therefore allows a few
//! pixels a step or two apart ([`GOLDEN_TOLERANCE`]) and prints what it found; a real change
//! moves pixels further or moves many. Drivers differ by more than that, hence a set each
//! ([`golden_dir`]); on a driver without a set the test says so and compares nothing.
//! Comparisons of two images from one run on one machine (technique against technique,
//! culling on against off) stay exact where they were: they live in the other tests.

use crate::common;
use crate::common::view;

use ml_cpu::bench_scene::bench_scene;
use ml_cpu::gltf_writer::{png, quad, quarters, GltfWriter, PrimitiveData};
use ml_cpu::lights::LightParams;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::random_scene::random_scene;
use ml_cpu::scene::Scene;
use ml_render::{DebugView, OmniShadowMode, OmniShadowSettings, RenderOutput, RenderSettings, ShadingModel, Technique};
use serde_json::json;
use std::path::PathBuf;

const W: u32 = 96;
const H: u32 = 64;

/// How far a render may stray from a committed image: no channel more than `max_step`/255
/// away, and at most `max_pixels` pixels different at all.
#[derive(Clone, Copy, Debug)]
struct Tolerance {
    max_step: u8,
    max_pixels: usize,
}

/// Rounding, not change: two steps (the techniques' own tolerance against each other) on at
/// most 1 % of a 96×64 image's pixels.
const GOLDEN_TOLERANCE: Tolerance = Tolerance { max_step: 2, max_pixels: (W * H / 100) as usize };

/// How two RGBA images differ: the largest channel difference, and how many pixels differ.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Difference {
    worst: u8,
    pixels: usize,
}

/// The images of one driver (Vulkan's driver name, lower case: `llvmpipe` is Mesa's lavapipe,
/// what CI runs; `nvidia`), each set blessed on its driver. Drivers differ by more than
/// rounding — on the H200, sharp pbr highlights by up to 47/255 and minified textures (another
/// level of detail) on up to 18 % of the pixels — so each is compared with its own.
fn golden_dir(driver: &str) -> PathBuf {
    let name: String = driver.to_lowercase().chars().filter(|c| c.is_ascii_alphanumeric() || *c == '-').collect();
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden").join(name)
}

/// The driver CI runs, whose set must be there.
const CI_DRIVER: &str = "llvmpipe";

/// One golden render: a scene, its shading model, point-light shadows, debug view, and the
/// techniques it is rendered with.
struct Case {
    name: String,
    scene: Scene,
    shading: ShadingModel,
    omni: Option<OmniShadowSettings>,
    view: DebugView,
    techniques: Vec<Technique>,
}

impl Case {
    fn new(name: &str, scene: Scene, shading: ShadingModel) -> Case {
        Case { name: name.into(), scene, shading, omni: None, view: DebugView::NONE, techniques: Technique::ALL.to_vec() }
    }
}

/// Quads with every glTF texture (base colour, normal, metallic-roughness, occlusion,
/// emissive) under a few lights: the G-buffer with its material images, the textured shaders.
fn textured_gltf() -> Scene {
    let mut w = GltfWriter::new();
    let texture = w.texture(png(4, 4, &quarters()), "image/png");
    let normal = w.texture(png(2, 2, &[128, 160, 230, 255, 160, 128, 230, 255, 128, 100, 230, 255, 100, 128, 230, 255]), "image/png");
    let m = w.textured_material(Some(texture), Some(normal));
    for key in ["occlusionTexture", "emissiveTexture"] {
        w.json["materials"][m][key] = json!({ "index": texture });
    }
    w.json["materials"][m]["pbrMetallicRoughness"]["metallicRoughnessTexture"] = json!({ "index": texture });
    w.json["materials"][m]["emissiveFactor"] = json!([0.3, 0.2, 0.1]);
    let plain = w.material([0.7, 0.5, 0.3, 1.0], 0.2, 0.4);
    for (material, x) in [(m, -1.1), (plain, 1.1)] {
        let mesh = w.mesh(&[PrimitiveData { material: Some(material), ..quad() }]);
        let facing = glam::Quat::from_rotation_x(0.9);
        w.node(json!({ "mesh": mesh, "translation": [x, 0.0, 0.0], "rotation": facing.to_array() }), true);
    }
    let camera = w.camera(json!({ "type": "perspective", "perspective": { "yfov": 0.9, "znear": 0.1, "zfar": 50.0 } }));
    w.node(json!({ "camera": camera, "translation": [0.0, 0.0, 4.0] }), true);
    for (i, at) in [[-1.0, 0.5, 1.0], [1.0, -0.5, 1.0], [0.0, 0.0, 2.0]].into_iter().enumerate() {
        let colour = [[1.0, 0.3, 0.3], [0.3, 1.0, 0.3], [0.4, 0.4, 1.0]][i];
        let light = w.light(json!({ "type": "point", "color": colour, "intensity": 3.0, "range": 4.0 }));
        w.node(json!({ "extensions": { "KHR_lights_punctual": { "light": light } }, "translation": at }), true);
    }
    let (scene, warnings) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    assert!(warnings.is_empty(), "{warnings:?}");
    scene
}

fn cases() -> Vec<Case> {
    let seed_lights = LightParams::seed_default();
    let seed = Scene::seed(MeshKind::Sphere, Material::named("gold").expect("named"), &seed_lights).expect("seed scene");
    let teapots = Scene::seed(MeshKind::Teapot, Material::named("copper").expect("named"), &seed_lights).expect("seed scene");
    let omni = Some(OmniShadowSettings { mode: OmniShadowMode::Layered, lights: 1, all: false, size: 64 });
    let mut cases = vec![
        Case::new("seed", seed.clone(), ShadingModel::Seed),
        Case::new("seed-blinn-phong", teapots.clone().with_floor(), ShadingModel::BlinnPhong),
        Case { omni, ..Case::new("room-pbr-omni", Scene::shadow_room(), ShadingModel::Pbr) },
        Case::new("bench", bench_scene(4096, 1, ml_cpu::bench_scene::BENCH_OBJECTS).expect("bench scene"), ShadingModel::Seed),
        Case::new("random-7", random_scene(7, 300), ShadingModel::Seed),
        Case::new("random-11-pbr", random_scene(11, 2000), ShadingModel::Pbr),
        Case::new("gltf-textured-pbr", textured_gltf(), ShadingModel::Pbr),
    ];
    // Debug views: what every technique shows of its surfaces, and the views of one kind of pass.
    for view in [view("gbuffer-normal"), view("gbuffer-material"), view("depth")] {
        cases.push(Case { view, ..Case::new(&format!("view-{}", view.name()), seed.clone(), ShadingModel::Seed) });
    }
    cases.push(Case { view: view("gbuffer-albedo"), ..Case::new("view-gbuffer-albedo-gltf", textured_gltf(), ShadingModel::Pbr) });
    let clustered_forward = vec![Technique::ClusteredCpu, Technique::ClusteredGpu];
    cases.push(Case {
        view: view("cluster-heat"),
        techniques: clustered_forward,
        ..Case::new("view-cluster-heat", seed, ShadingModel::Seed)
    });
    let shadow_map = Case::new("view-shadow-map", teapots.with_floor(), ShadingModel::BlinnPhong);
    cases.push(Case { view: view("shadow-map"), ..shadow_map });
    cases.push(Case { view: view("shadow-cube"), omni, ..Case::new("view-shadow-cube", Scene::shadow_room(), ShadingModel::Pbr) });
    cases
}

fn file_of(driver: &str, scene: &str, t: Technique) -> PathBuf {
    golden_dir(driver).join(format!("{scene}-{}.png", t.name()))
}

/// Compare a render (`width`×`height` RGBA) with the committed image at `path`: the
/// difference found, or why it is too large.
fn compare_with_file(name: &str, path: &std::path::Path, (width, height, rgba): (u32, u32, &[u8])) -> Result<Difference, String> {
    let golden =
        image::open(path).map_err(|e| format!("{name}: cannot read '{}': {e} (bless with MANYLIGHTS_BLESS=1)", path.display()))?.to_rgba8();
    if (golden.width(), golden.height()) != (width, height) {
        return Err(format!("{name}: golden image is {}x{}, render {width}x{height}", golden.width(), golden.height()));
    }
    let (worst, pixels) = common::rgba_difference(golden.as_raw(), rgba);
    let d = Difference { worst, pixels };
    let Tolerance { max_step, max_pixels } = GOLDEN_TOLERANCE;
    if d.worst > max_step || d.pixels > max_pixels {
        return Err(format!(
            "{name}: {} pixels differ from '{}', by up to {}/255 (allowed: {max_pixels} pixels, {max_step}/255)",
            d.pixels,
            path.display(),
            d.worst
        ));
    }
    Ok(d)
}

fn compare(driver: &str, scene: &str, t: Technique, out: &RenderOutput) -> Result<Difference, String> {
    compare_with_file(&format!("{scene} {}", t.name()), &file_of(driver, scene, t), (out.width, out.height, &out.rgba))
}

#[test]
fn every_technique_renders_the_golden_images() {
    let bless = std::env::var_os("MANYLIGHTS_BLESS").is_some();
    let mut failures = Vec::new();
    let (mut worst, mut most_pixels) = (0u8, 0usize);
    for case in cases() {
        let settings: Vec<RenderSettings> = case
            .techniques
            .iter()
            .map(|&t| {
                let mut s = RenderSettings::new(t, W, H);
                s.shading = case.shading;
                s.omni = case.omni;
                s.debug_view = case.view;
                // Two frames: both frames in flight build or upload their own lists; a fixed
                // clock keeps the lights where the images have them.
                s.frames = 2;
                s.time = Some(0.3);
                s
            })
            .collect();
        let (outputs, driver) = common::render_each_on_driver(&case.scene, &settings);
        if !bless && !golden_dir(&driver).is_dir() {
            assert_ne!(golden_dir(&driver), golden_dir(CI_DRIVER), "the CI driver's golden images are missing");
            println!(
                "no golden images for driver '{driver}' (sets: tests/golden/*): nothing compared; bless a set with MANYLIGHTS_BLESS=1"
            );
            return;
        }
        for (t, out) in case.techniques.iter().zip(&outputs) {
            if bless {
                std::fs::create_dir_all(golden_dir(&driver)).expect("golden folder");
                image::save_buffer(file_of(&driver, &case.name, *t), &out.rgba, out.width, out.height, image::ColorType::Rgba8)
                    .expect("write golden");
                continue;
            }
            match compare(&driver, &case.name, *t, out) {
                Ok(d) => {
                    println!("{} {}: {} pixels differ, by up to {}/255", case.name, t.name(), d.pixels, d.worst);
                    worst = worst.max(d.worst);
                    most_pixels = most_pixels.max(d.pixels);
                }
                Err(e) => failures.push(e),
            }
        }
    }
    println!("worst over every image: {most_pixels} pixels differ, by up to {worst}/255");
    assert!(failures.is_empty(), "{} images differ:\n{}", failures.len(), failures.join("\n"));
}

/// The comparison itself, on a committed image: rounding passes, changes fail.
#[test]
fn the_comparison_passes_rounding_and_fails_changes() {
    let path = file_of(CI_DRIVER, "seed", Technique::Forward);
    let golden = image::open(&path).expect("a committed image").to_rgba8();
    let (w, h) = golden.dimensions();
    // Pixels spread over the image, each channel moved by `step` (down where it would overflow).
    let perturbed = |pixels: usize, step: u8| {
        let mut rgba = golden.as_raw().clone();
        let count = (w * h) as usize;
        for i in 0..pixels {
            let p = (i * 7919) % count;
            for c in &mut rgba[p * 4..p * 4 + 3] {
                *c = if *c > 255 - step { *c - step } else { *c + step };
            }
        }
        compare_with_file("perturbed", &path, (w, h, &rgba))
    };
    assert_eq!(perturbed(0, 1), Ok(Difference { worst: 0, pixels: 0 }));
    assert_eq!(perturbed(8, 1), Ok(Difference { worst: 1, pixels: 8 }), "a few pixels by 1/255 are rounding");
    assert_eq!(perturbed(8, 2), Ok(Difference { worst: 2, pixels: 8 }));
    assert_eq!(perturbed(GOLDEN_TOLERANCE.max_pixels, 1).map(|d| d.pixels), Ok(GOLDEN_TOLERANCE.max_pixels));
    for (pixels, step) in [(1, 3), (8, 5), (3, 40), (GOLDEN_TOLERANCE.max_pixels + 1, 1), (600, 1), ((w * h) as usize, 1)] {
        let verdict = perturbed(pixels, step);
        assert!(verdict.is_err(), "{pixels} pixels moved by {step}/255 must fail, got {verdict:?}");
    }
    let err = perturbed(600, 1).unwrap_err();
    assert!(err.contains("600 pixels differ") && err.contains("up to 1/255"), "{err}");
}
