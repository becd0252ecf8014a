//! The light counts (`RenderSettings::light_stats`): on a wall that fills the view under
//! random lights (crossing the near plane, behind the camera and the wall, tiny and huge
//! radii), the lights tested per pixel equal what the CPU model of the light grid
//! (`ml_cpu::light_grid`) lists in the cells each pixel's point walks, and the lights reaching
//! equal a CPU count over every light at each pixel's point on the wall — in both compute-lit techniques (and the visibility technique's two rasters),
//! with validation on.

use crate::common;
use glam::{Mat4, Quat, Vec3};
use ml_cpu::camera::Camera;
use ml_cpu::gpu_types::PointLight;
use ml_cpu::light_grid::{bindable_cells, cell_budget, cpu_lists, tested_at, LightGridShape};
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{Object, Scene};
use ml_render::{LightStats, Raster, RenderSettings, Renderer, Technique};

const W: u32 = 96;
const H: u32 = 64;

/// A wall at z = 0 filling the view of a camera at z = 5, and `count` random lights.
fn wall_scene(count: usize, seed: u64) -> Scene {
    let rotation = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let mut wall = Object::placed(MeshKind::Plane, Vec3::ZERO, 1.0, Material { albedo: Vec3::splat(0.7), roughness: 0.6, metallic: 0.0 });
    wall.transform = Mat4::from_scale_rotation_translation(Vec3::new(20.0, 1.0, 20.0), rotation, Vec3::ZERO);
    let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    let mut next = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let lights = (0..count)
        .map(|i| {
            let p = Vec3::new(next() * 14.0 - 7.0, next() * 10.0 - 5.0, next() * 8.0 - 2.0);
            // Mostly small, one in sixteen huge.
            let radius = if i % 16 == 0 { 2.0 + next() * 4.0 } else { 0.05 + next() * 0.8 };
            PointLight { position_radius: [p.x, p.y, p.z, radius], color: [1.0, 1.0, 1.0, 0.0] }
        })
        .collect();
    let camera = Camera::looking_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, 60.0, 0.1, 30.0);
    let mut s = Scene::new(vec![wall], lights, camera);
    s.light_motion = 0.0;
    s
}

/// The CPU's counts: per pixel, its point on the wall (z = 0), the lights of the grid's
/// cells it walks (tested) and every light whose sphere holds the point (reaching).
fn cpu_counts(scene: &Scene, grid: &LightGridShape) -> LightStats {
    let mut s = LightStats::default();
    let lists = cpu_lists(grid, &scene.lights, Vec3::ZERO);
    for y in 0..H {
        for x in 0..W {
            let (o, d) = scene.camera.pixel_ray(x, y, W, H);
            let p = o + d * (-o.z / d.z);
            s.pixels += 1;
            s.tested += tested_at(grid, &lists, Vec3::ZERO, p) as u64;
            s.reached +=
                scene.lights.iter().filter(|l| (Vec3::from_slice(&l.position_radius[..3]) - p).length() < l.position_radius[3]).count()
                    as u64;
        }
    }
    s
}

#[test]
fn the_counts_equal_the_lists_and_a_cpu_count_of_the_lights_reaching() {
    let ctx = common::pooled_context();
    let variants = [
        (Technique::DeferredCompute, Raster::Hardware),
        (Technique::Visibility, Raster::Hardware),
        (Technique::Visibility, Raster::compute(Raster::DEFAULT_SPLIT)),
    ];
    for (i, seed) in [1u64, 2].into_iter().enumerate() {
        let scene = wall_scene(400 + 300 * i, seed);
        for (technique, raster) in variants {
            let settings = RenderSettings { light_stats: true, raster, ..RenderSettings::new(technique, W, H) };
            let mut renderer = Renderer::new(&ctx, scene.clone(), settings).expect("renderer");
            let out = renderer.render().expect("render");
            drop(renderer);
            let got = *out.stats.feature::<LightStats>().expect("the light counts");
            let bindable = bindable_cells(ctx.info.limits.max_storage_buffer_range);
            let grid = LightGridShape::fit(&scene.lights, cell_budget(scene.lights.len(), bindable));
            let want = cpu_counts(&scene, &grid);
            let name = format!("{} ({}), scene {seed}", technique.name(), raster.name());
            assert_eq!(got.pixels, want.pixels, "{name}: every pixel has the wall");
            // A pixel whose point lies within float rounding of a cell's boundary or a sphere
            // may land on the other side on the GPU: at most a few.
            let near = |a: u64, b: u64| a.abs_diff(b) as f64 <= 0.002 * b as f64 + 2.0;
            assert!(near(got.tested, want.tested), "{name}: tested {} against the lists' {}", got.tested, want.tested);
            assert!(near(got.reached, want.reached), "{name}: reaching {} against the CPU's {}", got.reached, want.reached);
            assert!(2 * got.reached > got.pixels && 4 * got.tested > 5 * got.reached, "{name}: a scene that tests the counts: {got:?}");
            println!("{name}: {got:?} (CPU: {want:?})");
        }
    }
}
