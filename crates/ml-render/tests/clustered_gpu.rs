//! clustered-gpu: the GPU-built cluster lists, read back, against the CPU assignment on random
//! scenes; and a hundred thousand lights on lavapipe without a validation message.

mod common;

use glam::{Vec3A, Vec4Swizzles};
use ml_cpu::cluster::{ClusterAssigner, ClusterDims, ClusterGrid, ClusterLists};
use ml_cpu::lights::{animate_into, LightLayout, LightParams, RadiusRange};
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::random_scene::random_scene;
use ml_cpu::scene::Scene;
use ml_render::{RenderError, RenderSettings, Renderer, Technique};
use ml_vk::{Context, ContextDesc};
use std::sync::atomic::Ordering;

const W: u32 = 160;
const H: u32 = 90;

/// Both builders run the same test (per-slice slab rectangle, then sphere vs the cluster's
/// box), the GPU in its own f32 arithmetic (`pow`, `log`, its own box corners). They must list
/// the same (light, cluster) pairs, except pairs where the sphere only grazes the box — within
/// `BORDER` of its radius, relative to the light's distance — which either side may round
/// either way and which light nothing (the light's weight there is ≤ (BORDER·d/r)²).
const BORDER: f32 = 1e-3;

#[test]
fn gpu_lists_equal_the_cpu_assignment_on_random_scenes() {
    let ctx = Context::new(&ContextDesc { validation: true, ..Default::default() }).expect("Vulkan with validation");
    let counter = ctx.validation_counter();
    let (mut pairs, mut borderline) = (0usize, 0usize);
    for seed in 0..20 {
        // The seed's tiny grid, the default, and a fine one whose scan spans 72 blocks (with
        // fewer lights there: radii up to 40 on 74k clusters would outgrow a storage buffer).
        let (dims, max_lights) = match seed % 5 {
            4 => (ClusterDims { x: 4, y: 4, z: 2 }, 5000),
            2 => (ClusterDims { x: 64, y: 36, z: 32 }, 200),
            _ => (ClusterDims::DEFAULT, 5000),
        };
        let scene = random_scene(3000 + seed, max_lights);
        let mut settings = RenderSettings::new(Technique::ClusteredGpu, W, H);
        settings.clusters = dims;
        settings.frames = 2;
        let mut renderer = Renderer::new(&ctx, scene.clone(), settings).expect("renderer");
        renderer.render().expect("render");
        let gpu = renderer.gpu_cluster_lists().expect("read back").expect("clustered-gpu lists");
        drop(renderer);

        let grid = ClusterGrid::new(dims, W, H, &scene.camera);
        let mut lights = scene.lights.clone();
        animate_into(&scene.lights, settings.clock(settings.frames - 1), &mut lights);
        let mut cpu = ClusterLists::default();
        ClusterAssigner::new().assign(&grid, &lights, &mut cpu, usize::MAX).expect("no limit");

        for cluster in 0..dims.count() as u32 {
            let (g, c) = (gpu.lights_of(cluster), cpu.lights_of(cluster));
            assert!(g.windows(2).all(|w| w[0] < w[1]), "gpu_cluster_lists sorts every list");
            pairs += c.len();
            for &light in symmetric_difference(g, c).iter() {
                let l = &lights[light as usize];
                let centre = (grid.view * glam::Vec4::new(l.position_radius[0], l.position_radius[1], l.position_radius[2], 1.0)).xyz();
                let r = l.position_radius[3];
                let distance = grid.bounds[cluster as usize].distance_squared(Vec3A::from(centre)).sqrt();
                let in_gpu = g.binary_search(&light).is_ok();
                assert!(
                    (distance - r).abs() <= BORDER * (r + centre.length()),
                    "scene {seed}, cluster {cluster}: light {light} (r {r}, {distance} from the box) is {} the GPU's list only",
                    if in_gpu { "in" } else { "missing from" }
                );
                borderline += 1;
            }
        }
    }
    drop(ctx);
    assert_eq!(counter.load(Ordering::SeqCst), 0, "validation messages");
    println!("{pairs} (light, cluster) pairs over 20 scenes; {borderline} differ, all grazing a box within {BORDER} of the radius");
    assert!(pairs > 100_000);
    assert!(borderline * 1000 < pairs, "too many grazing differences: {borderline} of {pairs}");
}

fn symmetric_difference(a: &[u32], b: &[u32]) -> Vec<u32> {
    let mut out: Vec<u32> = a.iter().filter(|x| b.binary_search(x).is_err()).copied().collect();
    out.extend(b.iter().filter(|x| a.binary_search(x).is_err()));
    out
}

#[test]
fn a_hundred_thousand_lights_render_cleanly() {
    let lights = LightParams { count: 100_000, layout: LightLayout::Random, seed: 7, radius: RadiusRange { min: 0.5, max: 1.5 } };
    let scene = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &lights).unwrap();
    let out = common::render(scene, RenderSettings::new(Technique::ClusteredGpu, 320, 180));
    let c = out.stats.clusters.expect("cluster stats");
    println!("100k lights: {} list entries, max {} per cluster", c.index_len, c.max_lights);
    assert!(c.index_len > 100_000, "the lights should land in many clusters");
}

#[test]
fn lists_larger_than_a_storage_buffer_fail_loudly() {
    // 1,000 lights of radius 40 on a fine grid need ~240 MiB of list: more than lavapipe
    // binds (128 MiB). Both builders must say so, not render short lists.
    let lights = LightParams { count: 1000, layout: LightLayout::Random, seed: 3, radius: RadiusRange::fixed(40.0) };
    let scene = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &lights).unwrap();
    let ctx = Context::new(&ContextDesc { validation: true, ..Default::default() }).expect("Vulkan with validation");
    let counter = ctx.validation_counter();
    let limit = ctx.info.limits.max_storage_buffer_range as u64;
    for technique in [Technique::ClusteredCpu, Technique::ClusteredGpu] {
        let mut settings = RenderSettings::new(technique, 64, 36);
        settings.clusters = ClusterDims { x: 64, y: 36, z: 32 };
        let result = Renderer::new(&ctx, scene.clone(), settings).and_then(|mut r| r.render());
        match result {
            Err(e) => {
                let text = e.to_string();
                assert!(matches!(e, RenderError::ListsTooLong(_)), "{}: {text}", technique.name());
                assert!(text.contains("light lists need") && text.contains("coarser cluster grid"), "{}: {text}", technique.name());
            }
            Ok(out) => {
                // Only a device that binds enough may succeed, and then with every entry.
                let c = out.stats.clusters.expect("stats");
                assert!(c.index_len as u64 * 4 <= limit, "{}: {} entries rendered past the limit", technique.name(), c.index_len);
            }
        }
    }
    drop(ctx);
    assert_eq!(counter.load(Ordering::SeqCst), 0, "validation messages");
}
