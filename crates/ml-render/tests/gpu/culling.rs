//! GPU culling is never visible (docs/DESIGN.md#gpu-culling): the visibility technique with
//! culling on and off gives the same image, frame by frame (but for up to 3 pixels in all on
//! the edge between two surfaces, which lavapipe gives to either in different runs:
//! `on_an_edge`), along 10 random camera paths of 30 frames — low cameras among the objects and behind walls, so that meshlets are occluded and
//! come out from behind occluders, back faces turn away, objects leave and enter the frustum —
//! each path with a camera cut halfway (the early phase then draws last frame's visible set
//! from a different place: the late phase must find everything else); then 3 of the paths
//! with anti-aliasing's samples. Validation (with synchronization validation) stays silent
//! throughout.

use crate::common;

use glam::{Mat4, Quat, Vec3};
use ml_cpu::camera::Camera;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::random_scene::random_scene;
use ml_cpu::scene::{Object, Scene};
use ml_render::{Antialiasing, CullStats, RenderOutput, RenderSettings, Renderer, Technique};
use ml_vk::Context;
use rand::{Rng, SeedableRng};

const W: u32 = 96;
const H: u32 = 64;
const PATHS: u64 = 10;
const FRAMES: u32 = 30;

/// A third of the random scene's object grid (lavapipe's time), with walls between its rows
/// (occluders). Objects the walls would cut are left out, and so are teapots, whose spout and
/// handle cross the body: where two surfaces cross, their depths agree to within rounding
/// along the crossing, and which one a pixel there shows depends on the order they are drawn
/// in — an order no GPU renderer fixes (atomics decide it, from run to run) and culling
/// changes. What this test proves is that culling removes nothing visible.
fn walled_scene() -> Scene {
    let mut scene = random_scene(3, 40);
    let walls: Vec<Mat4> = (0..3)
        .map(|i| {
            let z = -5.0 + 5.0 * i as f32 + 1.25;
            Mat4::from_scale_rotation_translation(Vec3::new(6.0, 1.5, 0.1), Quat::IDENTITY, Vec3::new(-2.0 + 2.0 * i as f32, 0.5, z))
        })
        .collect();
    let cube = scene.mesh(MeshKind::Cube).expect("the cube mesh");
    let bounds = |transform: Mat4, mesh: &ml_cpu::mesh::Mesh| {
        let points = mesh.vertices.iter().map(|v| transform.transform_point3(Vec3::from_array(v.position)));
        points.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)))
    };
    let wall_bounds: Vec<_> = walls.iter().map(|&w| bounds(w, &cube)).collect();
    let objects = std::mem::take(&mut scene.objects);
    for object in objects.into_iter().step_by(3) {
        let (lo, hi) = bounds(object.transform, &scene.mesh(object.mesh).expect("the object's mesh"));
        if object.mesh != MeshKind::Teapot && wall_bounds.iter().all(|(wlo, whi)| hi.cmplt(*wlo).any() || lo.cmpgt(*whi).any()) {
            scene.objects.push(object);
        }
    }
    for transform in walls {
        scene.objects.push(Object { transform, ..Object::placed(MeshKind::Cube, Vec3::ZERO, 1.0, Material::named("white").unwrap()) });
    }
    scene
}

/// A camera moving through the scene at object height, with a cut to another place halfway.
fn path(seed: u64) -> Vec<Camera> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let place = |rng: &mut rand_chacha::ChaCha8Rng| {
        let eye = Vec3::new(rng.random_range(-12.0..12.0), rng.random_range(0.3..4.0), rng.random_range(-12.0..12.0));
        let step = Vec3::new(rng.random_range(-0.6..0.6), rng.random_range(-0.05..0.05), rng.random_range(-0.6..0.6));
        let target = Vec3::new(rng.random_range(-6.0..6.0), 0.0, rng.random_range(-6.0..6.0));
        (eye, step, target)
    };
    let (mut a, mut b) = (place(&mut rng), place(&mut rng));
    (0..FRAMES)
        .map(|i| {
            if i == FRAMES / 2 {
                std::mem::swap(&mut a, &mut b);
            }
            let (eye, step, target) = a;
            let k = (i % (FRAMES / 2)) as f32;
            Camera::looking_at(eye + step * k, target, 60.0, 0.1, 200.0)
        })
        .collect()
}

/// Whether pixel `k`, which differs between `a` and `b`, is one the rasteriser may give to
/// either of two surfaces as it likes: its centre lies on the edge between them, and which one
/// it shows depends on the order their triangles are drawn in — an order the culling's atomics
/// change from run to run (lavapipe, same binary: one pixel of one frame in 600, in 4 of
/// 11 runs on an object's silhouette against the background, in 2 of ~18 against a wall
/// behind it). Accepted where each image shows at the pixel a colour the other shows right
/// next to it (within 3/255; shading varies a little along a surface), or, on a silhouette,
/// background in one image and the object in the other with both among the neighbours in each.
/// A culled triangle that should have been drawn leaves a colour its surroundings in the
/// culled image do not have, or more pixels than the few the test allows in all.
fn on_an_edge(a: &RenderOutput, b: &RenderOutput, k: usize) -> bool {
    let background = [5u8, 5, 5];
    let at = common::pixel_at;
    let (x, y) = ((k % W as usize) as i64, (k / W as usize) as i64);
    let around = |o: &RenderOutput| -> Vec<[u8; 3]> {
        (-1..=1)
            .flat_map(|dy| (-1..=1).map(move |dx| (dx, dy)))
            .filter(|d| *d != (0, 0))
            .filter_map(|(dx, dy)| at(o, x + dx, y + dy))
            .collect()
    };
    let near = |p: [u8; 3], q: [u8; 3]| p.iter().zip(q).all(|(u, v)| u.abs_diff(v) <= 3);
    let (pa, pb) = (at(a, x, y).expect("inside"), at(b, x, y).expect("inside"));
    let swapped = around(b).iter().any(|&q| near(pa, q)) && around(a).iter().any(|&q| near(pb, q));
    let one_is_background = (pa == background) != (pb == background);
    let mixed = |o: &RenderOutput| {
        let n = around(o);
        n.contains(&background) && n.iter().any(|p| *p != background)
    };
    swapped || (one_is_background && mixed(a) && mixed(b))
}

#[test]
fn culling_on_and_off_give_the_same_frames() {
    let ctx = common::pooled_context();
    let scene = walled_scene();
    // Without anti-aliasing, and with samples (the pyramid's first level is read from them
    // otherwise: depth_pyramid_samples.comp) on fewer paths.
    for (antialiasing, paths) in [(Antialiasing::Off, PATHS), (Antialiasing::X4, 3)] {
        let (occluded, late_drawn) = compare_culling(&ctx, &scene, antialiasing, paths);
        // The paths must exercise both phases, or the test proves nothing.
        assert!(occluded > 0 && late_drawn > 0, "{antialiasing:?}");
    }
}

/// `paths` camera paths rendered with culling on and off at `antialiasing`: the frames equal
/// but for a few edge pixels; returns the meshlet tests culled and the meshlets the late phase
/// drew.
fn compare_culling(ctx: &Context, scene: &Scene, antialiasing: Antialiasing, paths: u64) -> (u64, u64) {
    let mut on = RenderSettings::new(Technique::Visibility, W, H);
    on.frames = 1;
    on.antialiasing = antialiasing;
    let off = RenderSettings { culling: false, ..on };
    let mut renderers = [Renderer::new(ctx, scene.clone(), on).unwrap(), Renderer::new(ctx, scene.clone(), off).unwrap()];
    let (mut occluded, mut late_drawn, mut frames, mut edge_pixels) = (0u64, 0u64, 0, 0);
    for p in 0..paths {
        for (i, camera) in path(p).into_iter().enumerate() {
            let mut images = Vec::new();
            for r in &mut renderers {
                r.set_camera(camera).unwrap();
                images.push(r.render().unwrap());
            }
            let (a, b) = (&images[0], &images[1]);
            let differing: Vec<usize> =
                a.rgba.chunks_exact(4).zip(b.rgba.chunks_exact(4)).enumerate().filter(|(_, (x, y))| x != y).map(|(k, _)| k).collect();
            for &k in &differing {
                assert!(on_an_edge(a, b, k), "path {p} frame {i}: pixel {k} differs between culling on and off");
            }
            edge_pixels += differing.len();
            let c = *a.stats.feature::<CullStats>().expect("culling stats");
            assert_eq!(
                b.stats.feature::<CullStats>().unwrap().early_drawn,
                b.stats.feature::<CullStats>().unwrap().meshlet_instances,
                "culling off draws every meshlet"
            );
            // Culled by occlusion or cones: tested late but neither drawn early nor late.
            occluded += (c.late_tested - c.early_drawn - c.late_drawn) as u64;
            late_drawn += c.late_drawn as u64;
            frames += 1;
        }
    }
    println!(
        "{antialiasing:?}: {frames} frames: {occluded} meshlet tests culled, {late_drawn} meshlets drawn by the late phase; {edge_pixels} edge pixels differ"
    );
    assert!(edge_pixels <= 3, "{antialiasing:?}: {edge_pixels} edge pixels differ in {frames} frames");
    (occluded, late_drawn)
}
