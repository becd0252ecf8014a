//! Every culling technique gives the brute-force image (SPEC §3): lights have a hard radius,
//! so correct culling changes no pixel. Random scenes with lights behind the camera,
//! straddling the near plane, around the eye, radii 0.2–40 (cameras inside light spheres)
//! and 1–5,000 lights, plus the seed scene; max channel difference ≤ 1/255.
//!
//! Both shaders sum the same lights in the same (ascending) order, so in practice the
//! images are identical; the 1/255 allowance covers compilers contracting the two loops'
//! arithmetic differently.

mod common;

use ml_cpu::cluster::ClusterDims;
use ml_cpu::lights::LightParams;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::random_scene::random_scene;
use ml_cpu::scene::Scene;
use ml_render::{RenderSettings, Technique};

const W: u32 = 160;
const H: u32 = 90;
const MAX_DIFF: u8 = 1;

/// Render with forward and each other technique (two frames, so both frames in flight
/// upload their own cluster data) and compare.
fn assert_matches_forward(name: &str, scene: &Scene, clusters: ClusterDims) -> u32 {
    let forward = RenderSettings::new(Technique::Forward, W, H);
    let mut clustered = RenderSettings::new(Technique::ClusteredCpu, W, H);
    clustered.clusters = clusters;
    clustered.frames = 2;
    let out = common::render_each(scene, &[forward, clustered]);
    let (worst, pixels) = common::max_difference(&out[0], &out[1]);
    let c = out[1].stats.clusters.expect("cluster stats");
    println!(
        "{name}: {} lights, clusters {}x{}x{}: max diff {worst}/255 in {pixels} pixels; lights/cluster mean {:.1} max {}; index growths {}",
        scene.lights.len(), clusters.x, clusters.y, clusters.z, c.mean_lights, c.max_lights, out[1].stats.index_growths
    );
    assert!(worst <= MAX_DIFF, "{name}: clustered-cpu differs from forward by {worst}/255");
    // The comparison means something only if lights actually reach visible surfaces.
    let lit = out[0].rgba.chunks_exact(4).filter(|p| p[0].max(p[1]).max(p[2]) > 60).count();
    assert!(lit > 0 || scene.lights.len() < 50, "{name}: nothing lit");
    out[1].stats.index_growths
}

#[test]
fn clustered_cpu_equals_forward_on_random_scenes() {
    let mut growths = 0;
    for seed in 0..20 {
        let scene = random_scene(1000 + seed, 5000);
        let dims = if seed % 4 == 3 { ClusterDims { x: 4, y: 4, z: 2 } } else { ClusterDims::DEFAULT };
        growths += assert_matches_forward(&format!("random scene {seed}"), &scene, dims);
    }
    assert!(growths > 0, "no scene made the light-index buffer grow: the growth path went untested");
}

#[test]
fn clustered_cpu_equals_forward_on_the_seed_scene() {
    for object in [MeshKind::Sphere, MeshKind::Teapot] {
        let scene = Scene::seed(object, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap();
        assert_matches_forward(&format!("seed scene ({})", object.name()), &scene, ClusterDims::DEFAULT);
        assert_matches_forward(&format!("seed scene ({}), seed grid", object.name()), &scene, ClusterDims { x: 4, y: 4, z: 2 });
    }
}

#[test]
fn cluster_heat_view_paints_counts_and_a_legend() {
    let scene = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap();
    let mut settings = RenderSettings::new(Technique::ClusteredCpu, 320, 180);
    settings.debug_view = ml_render::DebugView::ClusterHeat;
    let heat = common::render(scene.clone(), settings);
    // The legend's ramp spans x ∈ [2%, 35%] of the width near the bottom: black → red.
    let y = (180.0 * 0.915) as u32;
    let [r0, g0, b0] = common::pixel(&heat, (320.0 * 0.025) as u32, y);
    let [r1, g1, _] = common::pixel(&heat, (320.0 * 0.34) as u32, y);
    assert!(r0.max(g0).max(b0) < 40, "ramp should start black: {:?}", [r0, g0, b0]);
    assert!(r1 > 200 && g1 < 60, "ramp should end red: {:?}", [r1, g1]);
    // The objects show heat colours, not the shaded image.
    let shaded = common::render(scene, RenderSettings::new(Technique::ClusteredCpu, 320, 180));
    let (diff, pixels) = common::max_difference(&heat, &shaded);
    assert!(diff > 100 && pixels > 5000, "heat view looks like the shaded image ({pixels} pixels differ)");
}
