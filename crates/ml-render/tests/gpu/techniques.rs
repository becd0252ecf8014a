//! Every culling technique gives the brute-force image (docs/DESIGN.md#exactness): lights have
//! a hard radius, so correct culling changes no pixel. Random scenes with lights behind the
//! camera, straddling the near plane, around the eye, radii 0.2–40 (cameras inside light
//! spheres) and 1–5,000 lights, plus the seed scene; max channel difference ≤ 1/255.
//! clustered-gpu fills its lists with atomics, so a cluster's lights come in any order and the
//! float sum may round differently: that is what the 1/255 is for. The deferred techniques
//! (deferred and deferred-clustered: G-buffer subpass → lighting subpass → HDR → tone map;
//! deferred-compute: clustered-gpu's lists lit in a compute pass) are allowed 2/255, see
//! MAX_DIFF_DEFERRED.
//!
//! Both shaders sum the same lights in the same (ascending) order, so in practice the
//! images are identical; the 1/255 allowance covers compilers contracting the two loops'
//! arithmetic differently.

use crate::common;
use crate::common::view;

use ml_cpu::cluster::ClusterDims;
use ml_cpu::lights::LightParams;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::random_scene::random_scene;
use ml_cpu::scene::Scene;
use ml_render::{Antialiasing, Raster, RenderSettings, ShadingModel, Technique};

const W: u32 = 160;
const H: u32 = 90;
const MAX_DIFF: u8 = 1;
/// The deferred techniques rebuild the position from the depth buffer (instead of
/// interpolating it) and store the normal octahedrally in two floats: both move sharp
/// highlights by a few 1e-5, which at roughness 0.1 turns into at most 2/255 on a few pixels
/// per image. (The HDR target's half floats add at most ~1e-5 after gamma.)
const MAX_DIFF_DEFERRED: u8 = 2;

/// blinn-phong's sun shadow: the deferred paths look the shadow map up from a position rebuilt
/// from depth (off by ~1e-4 at 20 units with D32 and near 0.1), and a depth comparison near its
/// threshold flips for such a move (it is not continuous in the reference depth, whatever the
/// filter): measured, without the shadow lookup the same scenes differ by at most 1/255; with
/// it, 2 of 14,400 pixels by 9–21/255. So: at most this many pixels beyond MAX_DIFF_DEFERRED
/// per image, by at most MAX_DIFF_SHADOW_OUTLIER.
const SHADOW_OUTLIERS: usize = 8;
const MAX_DIFF_SHADOW_OUTLIER: u8 = 32;

/// Every technique but forward (the first), so a new one is compared without being listed.
const OTHERS: &[Technique] = Technique::ALL.split_at(1).1;
const _: () = assert!(matches!(Technique::ALL[0], Technique::Forward), "the reference comes first");

/// What a comparison saw, summed over scenes.
#[derive(Default)]
struct Seen {
    growths: u32,
}

/// Render with forward and each other technique (two frames, so both frames in flight build
/// or upload their own cluster data) and compare.
fn assert_matches_forward(name: &str, scene: &Scene, clusters: ClusterDims) -> Seen {
    assert_matches_forward_shaded(name, scene, clusters, ShadingModel::Seed)
}

fn assert_matches_forward_shaded(name: &str, scene: &Scene, clusters: ClusterDims, shading: ShadingModel) -> Seen {
    let mut forward = RenderSettings::new(Technique::Forward, W, H);
    forward.shading = shading;
    let mut settings = vec![forward];
    for &t in OTHERS {
        let mut s = RenderSettings::new(t, W, H);
        s.shading = shading;
        s.clusters = clusters;
        s.frames = 2;
        settings.push(s);
    }
    let out = common::render_each(scene, &settings);
    let mut seen = Seen::default();
    for (t, o) in OTHERS.iter().zip(&out[1..]) {
        let (worst, pixels) = common::max_difference(&out[0], o);
        let c = o.stats.clusters.unwrap_or_default();
        assert_eq!(o.stats.clusters.is_some(), t.has_cluster_grid(), "{}: cluster stats", t.name());
        println!(
            "{name} {}: {} lights, clusters {}x{}x{}: max diff {worst}/255 in {pixels} pixels; lights/cluster mean {:.1} max {}; index growths {}",
            t.name(), scene.lights.len(), clusters.x, clusters.y, clusters.z, c.mean_lights, c.max_lights, o.stats.index_growths
        );
        let deferred = t.lights_in_compute() || t.lights_in_subpass();
        let allowed = if deferred { MAX_DIFF_DEFERRED } else { MAX_DIFF };
        if deferred && shading == ShadingModel::BlinnPhong {
            // See SHADOW_OUTLIERS: a few pixels may differ more, none by more than a ninth of the sun.
            let beyond = common::pixels_beyond(&out[0], o, allowed);
            println!("{name} {}: {beyond} pixels beyond {allowed}/255", t.name());
            assert!(beyond <= SHADOW_OUTLIERS, "{name}: {} differs from forward beyond {allowed}/255 in {beyond} pixels", t.name());
            assert!(worst <= MAX_DIFF_SHADOW_OUTLIER, "{name}: {} differs from forward by {worst}/255", t.name());
        } else {
            assert!(worst <= allowed, "{name}: {} differs from forward by {worst}/255", t.name());
        }
        seen.growths += o.stats.index_growths;
    }
    // The comparison means something only if lights actually reach visible surfaces.
    let lit = out[0].rgba.chunks_exact(4).filter(|p| p[0].max(p[1]).max(p[2]) > 60).count();
    assert!(lit > 0 || scene.lights.len() < 50, "{name}: nothing lit");
    seen
}

#[test]
fn every_technique_equals_forward_on_random_scenes() {
    let mut seen = Seen::default();
    // 12 scenes: each has lights behind the camera, across the near plane and around the eye,
    // radii from 0.2 to 40 (CI's time; more seeds found nothing new).
    let mut orthographic = 0;
    for seed in 0..12 {
        let scene = random_scene(1000 + seed, 5000);
        orthographic += usize::from(scene.camera.orthographic.is_some());
        let dims = if seed % 4 == 3 { ClusterDims { x: 4, y: 4, z: 2 } } else { ClusterDims::DEFAULT };
        let s = assert_matches_forward(&format!("random scene {seed}"), &scene, dims);
        seen.growths += s.growths;
    }
    // Radii up to 40 need far more list entries than the initial capacity: the CPU upload's
    // growth ran, and lost nothing (the light grid lists each light once: nothing to grow).
    assert!(seen.growths > 0, "growth paths went untested");
    assert!(orthographic > 0, "no orthographic camera among the scenes");
}

#[test]
fn every_technique_equals_forward_on_the_seed_scene() {
    for object in [MeshKind::Sphere, MeshKind::Teapot] {
        let scene = Scene::seed(object, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap();
        assert_matches_forward(&format!("seed scene ({})", object.name()), &scene, ClusterDims::DEFAULT);
        assert_matches_forward(&format!("seed scene ({}), seed grid", object.name()), &scene, ClusterDims { x: 4, y: 4, z: 2 });
    }
}

/// The blinn-phong model (docs/DESIGN.md#shading-models: textures, normal maps, a shadowed sun,
/// a spot light and reflections on top of the point lights) and the pbr model (diffuse +
/// specular, tone-mapped HDR): the same in every technique.
#[test]
fn every_technique_equals_forward_with_blinn_phong_and_pbr() {
    for model in [ShadingModel::BlinnPhong, ShadingModel::Pbr] {
        let gold = Material::named("gold").unwrap();
        for object in [MeshKind::Sphere, MeshKind::Teapot] {
            let scene = Scene::seed(object, gold, &LightParams::seed_default()).unwrap().with_floor();
            let name = format!("{} seed scene ({})", model.name(), object.name());
            assert_matches_forward_shaded(&name, &scene, ClusterDims::DEFAULT, model);
        }
        for seed in 0..2 {
            let scene = random_scene(2000 + seed, 2000);
            assert_matches_forward_shaded(&format!("{} random scene {seed}", model.name()), &scene, ClusterDims::DEFAULT, model);
        }
    }
}

#[test]
fn cluster_heat_view_paints_counts_and_a_legend() {
    let scene = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap();
    let mut settings = RenderSettings::new(Technique::ClusteredCpu, 320, 180);
    settings.debug_view = view("cluster-heat");
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

/// With anti-aliasing (4 samples a pixel, lavapipe's most for attachments), every technique
/// gives forward's anti-aliased image wherever a pixel's samples hold one surface. Where they
/// hold several (edge pixels: those that anti-aliasing changes in forward's image) each
/// technique shades a surface at the mean of its samples — forward of those its triangle covers
/// before the depth test, the others of those it holds after it — so there the differences are
/// counted and bounded, not required to vanish.
#[test]
fn every_technique_equals_forward_with_anti_aliasing() {
    let antialiased = Technique::ALL;
    assert_eq!(antialiased[0], Technique::Forward);
    assert_eq!(antialiased.last(), Some(&Technique::Visibility));
    // One random scene (CI's time): 1,000–3,000 edge pixels, enough to count.
    let seed = 0;
    let scene = random_scene(3000 + seed, 2000);
    let with_samples = |technique: Technique| {
        let raster = if technique == Technique::Visibility { Raster::compute(Raster::DEFAULT_SPLIT) } else { Raster::Hardware };
        RenderSettings { antialiasing: Antialiasing::X4, raster, frames: 2, ..RenderSettings::new(technique, W, H) }
    };
    // And visibility again, drawn by the hardware raster (its samples gathered into the
    // compute raster's buffer).
    let hardware = RenderSettings { raster: Raster::Hardware, ..with_samples(Technique::Visibility) };
    let settings: Vec<RenderSettings> = [RenderSettings::new(Technique::Forward, W, H)]
        .into_iter()
        .chain(antialiased.iter().map(|&t| with_samples(t)))
        .chain([hardware])
        .collect();
    let out = common::render_each(&scene, &settings);
    let differs = |a: &[u8], b: &[u8], allowed: u8| a.iter().zip(b).any(|(x, y)| x.abs_diff(*y) > allowed);
    let pixels = |o: &ml_render::RenderOutput| o.rgba.chunks_exact(4).map(<[u8]>::to_vec).collect::<Vec<_>>();
    let (off, forward) = (pixels(&out[0]), pixels(&out[1]));
    let edge: Vec<bool> = off.iter().zip(&forward).map(|(a, b)| differs(a, b, MAX_DIFF)).collect();
    let edges = edge.iter().filter(|&&e| e).count();
    assert!(edges > 0, "random scene {seed}: anti-aliasing changed no pixel of forward's image");
    for (s, o) in settings[2..].iter().zip(&out[2..]) {
        let raster = if s.technique == Technique::Visibility { format!(" ({} raster)", s.raster.name()) } else { String::new() };
        let t = format!("{}{raster}", s.technique.name());
        let mine = pixels(o);
        let (mut inside, mut at_edges, mut worst) = (0, 0, 0u8);
        for ((a, b), &e) in forward.iter().zip(&mine).zip(&edge) {
            let d = a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(0);
            if d > MAX_DIFF_DEFERRED {
                if e {
                    at_edges += 1;
                    worst = worst.max(d);
                } else {
                    inside += 1;
                }
            }
        }
        println!(
            "random scene {seed} with 4 samples, {t}: {edges} edge pixels; beyond {MAX_DIFF_DEFERRED}/255 at {at_edges} of them (up to {worst}/255), at {inside} others"
        );
        // A pixel or two of the visibility technique's differ where anti-aliasing left
        // forward's pixel as it was (an edge between like colours) and the shading points
        // differ (measured: at most 2 of 14,400 pixels, either raster).
        assert!(inside <= 8, "random scene {seed}: {t} differs from forward at {inside} pixels that hold one surface");
        assert!(at_edges * 2 <= edges, "random scene {seed}: {t} differs from forward at {at_edges} of {edges} edge pixels");
    }
}
