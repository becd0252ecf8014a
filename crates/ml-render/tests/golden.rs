//! Golden images: every technique on the seed, room, bench and random scenes (and the
//! blinn-phong and pbr models, point-light shadows, a textured glTF scene and the debug views), compared
//! byte for byte with PNGs kept in `tests/golden/`. Restructuring the renderer must not move a
//! pixel; a change that means to change images re-blesses them on purpose:
//!
//! ```sh
//! MANYLIGHTS_BLESS=1 cargo test -p ml-render --test golden
//! ```
//!
//! The images were rendered on Mesa lavapipe (what CI runs); another driver rounds
//! differently, so the comparison is exact only there and reports the largest difference
//! elsewhere (where it must stay within the techniques' own 2/255).

mod common;

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
/// Where the driver is not the one the images were made on: the techniques' own tolerance.
const MAX_DIFF_ELSEWHERE: u8 = 2;

fn golden_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

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
        Case { name: name.into(), scene, shading, omni: None, view: DebugView::None, techniques: Technique::ALL.to_vec() }
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
    for view in [DebugView::GBufferNormal, DebugView::GBufferMaterial, DebugView::Depth] {
        cases.push(Case { view, ..Case::new(&format!("view-{}", view.name()), seed.clone(), ShadingModel::Seed) });
    }
    cases.push(Case { view: DebugView::GBufferAlbedo, ..Case::new("view-gbuffer-albedo-gltf", textured_gltf(), ShadingModel::Pbr) });
    let clustered_forward = vec![Technique::ClusteredCpu, Technique::ClusteredGpu];
    cases.push(Case {
        view: DebugView::ClusterHeat,
        techniques: clustered_forward,
        ..Case::new("view-cluster-heat", seed, ShadingModel::Seed)
    });
    let shadow_map = Case::new("view-shadow-map", teapots.with_floor(), ShadingModel::BlinnPhong);
    cases.push(Case { view: DebugView::ShadowMap, ..shadow_map });
    cases.push(Case { view: DebugView::ShadowCube, omni, ..Case::new("view-shadow-cube", Scene::shadow_room(), ShadingModel::Pbr) });
    cases
}

fn file_of(scene: &str, t: Technique) -> PathBuf {
    golden_dir().join(format!("{scene}-{}.png", t.name()))
}

fn compare(scene: &str, t: Technique, out: &RenderOutput, exact: bool) -> Result<(), String> {
    let path = file_of(scene, t);
    let name = format!("{scene} {}", t.name());
    let golden = image::open(&path)
        .map_err(|e| format!("{name}: cannot read '{}': {e} (bless with MANYLIGHTS_BLESS=1)", path.display()))?
        .to_rgba8();
    if (golden.width(), golden.height()) != (out.width, out.height) {
        return Err(format!("{name}: golden image is {}x{}, render {}x{}", golden.width(), golden.height(), out.width, out.height));
    }
    let (mut worst, mut pixels) = (0u8, 0usize);
    for (a, b) in golden.as_raw().chunks_exact(4).zip(out.rgba.chunks_exact(4)) {
        let d = a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(0);
        worst = worst.max(d);
        pixels += usize::from(d > 0);
    }
    println!("{name}: max diff {worst}/255 in {pixels} pixels");
    let limit = if exact { 0 } else { MAX_DIFF_ELSEWHERE };
    if worst > limit {
        return Err(format!("{name}: {pixels} pixels differ from '{}', by up to {worst}/255 (allowed {limit})", path.display()));
    }
    Ok(())
}

#[test]
fn every_technique_renders_the_golden_images() {
    let bless = std::env::var_os("MANYLIGHTS_BLESS").is_some();
    let mut failures = Vec::new();
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
        let (outputs, lavapipe) = common::render_each_on_device(&case.scene, &settings);
        for (t, out) in case.techniques.iter().zip(&outputs) {
            if bless {
                std::fs::create_dir_all(golden_dir()).expect("golden folder");
                image::save_buffer(file_of(&case.name, *t), &out.rgba, out.width, out.height, image::ColorType::Rgba8)
                    .expect("write golden");
            } else if let Err(e) = compare(&case.name, *t, out, lavapipe) {
                failures.push(e);
            }
        }
    }
    assert!(failures.is_empty(), "{} images differ:\n{}", failures.len(), failures.join("\n"));
}
