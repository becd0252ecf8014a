//! The shadow atlas (docs/DESIGN.md#shadow-atlas) against the cube array and the CPU ray test:
//! with every face at the cube array's size the atlas gives its image (the filter is the same
//! 3×3 tent, written by hand over the atlas's texels: pixels more than 1/255 apart may only lie
//! on shadow edges, where the ray test is unsure, and are counted); the cache changes no
//! pixel, with the camera or the lights moving; a face some pixel samples is never left out;
//! the memory stays within the budget at 4,096 shadowed lights; absurd budgets are refused.

use crate::common;
use crate::common::view;

use common::shadow_rays::sure_pixels;
use glam::Vec3;
use ml_cpu::camera::Camera;
use ml_cpu::gpu_types::PointLight;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{Object, Scene};
use ml_render::settings::AtlasSettings;
use ml_render::AtlasStats;
use ml_render::{OmniShadowMode, OmniShadowSettings, RenderOutput, RenderSettings, Renderer, ShadingModel, Technique};
use ml_vk::{Context, ContextDesc};

/// The image side and the cube array's face side the atlas is compared with.
const SIZE: u32 = 96;
const CUBE: u32 = 128;

fn atlas(budget_mib: u32, cache: bool, fixed_size: Option<u32>) -> OmniShadowMode {
    OmniShadowMode::Atlas(AtlasSettings { budget_mib, cache, fixed_size })
}

fn settings(technique: Technique, shading: ShadingModel, omni: Option<(OmniShadowMode, u32)>) -> RenderSettings {
    let mut s = RenderSettings::new(technique, SIZE, SIZE);
    s.shading = shading;
    s.omni = omni.map(|(mode, lights)| OmniShadowSettings { mode, lights, all: false, size: CUBE });
    s
}

/// The room (a pillar, one white light) and a second, coloured light on the other side.
fn two_light_room() -> Scene {
    let mut scene = Scene::shadow_room();
    scene.lights.push(PointLight { position_radius: [3.0, -1.0, 3.5, 20.0], color: [1.0, 2.0, 3.0, 0.0] });
    scene
}

/// Pixels more than 1/255 apart, and those of them the ray test is sure of.
fn beyond_and_sure(a: &RenderOutput, b: &RenderOutput, sure: &[(u32, u32)]) -> (usize, Vec<(u32, u32)>) {
    let beyond = common::pixels_beyond(a, b, 1);
    let wrong = sure
        .iter()
        .copied()
        .filter(|&(x, y)| common::pixel(a, x, y).iter().zip(common::pixel(b, x, y)).any(|(p, q)| p.abs_diff(q) > 1))
        .collect();
    (beyond, wrong)
}

/// Every face at the cube array's size, a budget that holds them all: every technique (pbr)
/// and every shading model (forward) gives the cube array's image but on shadow edges.
#[test]
fn the_atlas_gives_the_cube_arrays_image() {
    let scene = two_light_room();
    let sure: Vec<(u32, u32)> = sure_pixels(&scene, SIZE, CUBE).into_iter().map(|(p, _)| p).collect();
    let mut cases: Vec<(Technique, ShadingModel)> = Technique::ALL.iter().map(|&t| (t, ShadingModel::Pbr)).collect();
    cases.extend([(Technique::Forward, ShadingModel::Seed), (Technique::Forward, ShadingModel::BlinnPhong)]);
    let mut all = Vec::new();
    for &(t, m) in &cases {
        all.push(settings(t, m, Some((OmniShadowMode::COMPUTE, 2))));
        all.push(settings(t, m, Some((atlas(256, true, Some(CUBE)), 2))));
    }
    all.push(settings(Technique::Forward, ShadingModel::Pbr, None));
    let outputs = common::render_each(&scene, &all);
    for (i, (t, m)) in cases.iter().enumerate() {
        let (cubes, atlas) = (&outputs[2 * i], &outputs[2 * i + 1]);
        let stats = *atlas.stats.feature::<AtlasStats>().expect("the atlas reports");
        assert_eq!(stats.divided_by, 1, "the budget holds every face at {CUBE}²");
        let (beyond, wrong) = beyond_and_sure(atlas, cubes, &sure);
        let (max, _) = common::max_difference(atlas, cubes);
        println!(
            "{} / {}: {beyond} of {} pixels > 1/255 from the cube array (max {max}/255), {} faces",
            t.name(),
            m.name(),
            SIZE * SIZE,
            stats.faces
        );
        assert!(wrong.is_empty(), "{} / {}: pixels off shadow edges differ: {:?}", t.name(), m.name(), &wrong[..wrong.len().min(12)]);
        assert!(beyond * 50 <= (SIZE * SIZE) as usize, "{} / {}: {beyond} pixels differ", t.name(), m.name());
    }
    // The shadows are there: the atlas's image is not the shadow-less one.
    let darker = common::pixels_beyond(&outputs[1], outputs.last().unwrap(), 20);
    assert!(darker > 100, "only {darker} pixels in shadow");
    assert!(sure.len() > 4000, "only {} pixels the ray test is sure of", sure.len());
}

/// Two renderers on one validated context, cache on and off; the layer says nothing.
fn with_pair(scene: &Scene, mut base: RenderSettings, budget_mib: u32, f: impl FnOnce(&mut Renderer, &mut Renderer)) {
    let ctx = common::pooled_context();
    {
        let lights = scene.lights.len() as u32;
        base.omni = Some(OmniShadowSettings { mode: atlas(budget_mib, true, None), lights, all: false, size: CUBE });
        let mut cached = Renderer::new(&ctx, scene.clone(), base).expect("renderer");
        base.omni = Some(OmniShadowSettings { mode: atlas(budget_mib, false, None), lights, all: false, size: CUBE });
        let mut uncached = Renderer::new(&ctx, scene.clone(), base).expect("renderer");
        f(&mut cached, &mut uncached);
    }
}

fn atlas_stats(out: &RenderOutput) -> AtlasStats {
    *out.stats.feature::<AtlasStats>().expect("the atlas reports")
}

/// Static lights, a camera walking round the room and turning: the faces come, go and change
/// size with the view; those kept from last frame give the same pixels as those drawn again.
#[test]
fn the_cache_changes_no_pixel_while_the_camera_moves() {
    let scene = two_light_room();
    let base = settings(Technique::Forward, ShadingModel::Pbr, None);
    // 32 MiB: the faces are divided to fit, as they are when the budget is short.
    with_pair(&scene, base, 32, |cached, uncached| {
        let (mut kept, mut drawn_again) = (0, 0);
        for i in 0..30 {
            let a = i as f32 / 30.0 * std::f32::consts::TAU;
            let eye = Vec3::new(3.5 * a.cos(), -1.0 + (a * 2.0).sin(), 3.5 * a.sin());
            // Looking across the room, sometimes up, sometimes at the floor.
            let target = Vec3::new(-2.0 * a.sin(), -2.0 * (a * 3.0).cos(), 2.0 * a.cos());
            let camera = Camera::looking_at(eye, target, 70.0, 0.05, 50.0);
            cached.set_camera(camera).expect("camera");
            uncached.set_camera(camera).expect("camera");
            let (on, off) = (cached.render().expect("render"), uncached.render().expect("render"));
            let (s, u) = (atlas_stats(&on), atlas_stats(&off));
            assert_eq!(u.redrawn, u.faces, "without the cache every face is drawn");
            assert_eq!((s.faces, s.divided_by), (u.faces, u.divided_by), "frame {i}: the same faces either way");
            assert_eq!(on.rgba, off.rgba, "frame {i}: cache on and off differ");
            if i > 0 {
                kept += s.faces - s.redrawn;
                drawn_again += s.redrawn;
            }
        }
        println!("frames 1–29: {kept} faces kept, {drawn_again} drawn (new, resized or laid out again)");
        assert!(kept > 0 && drawn_again > 0, "the camera should both keep faces and bring new ones");
    });
}

/// The seed's animation (every light moving, every face drawn every frame) over 10 frames,
/// then one light moved by hand: only its faces are drawn again, and the images never differ.
#[test]
fn the_cache_changes_no_pixel_while_lights_move() {
    let scene = two_light_room();
    let mut base = settings(Technique::Forward, ShadingModel::Pbr, None);
    base.frames = 10;
    base.time = None;
    with_pair(&scene, base, 64, |cached, uncached| {
        let (mut on, mut off) = (common::Frames::default(), common::Frames::default());
        let last_on = cached.render_into(&mut on).expect("render");
        uncached.render_into(&mut off).expect("render");
        assert_eq!(on.0.len(), 10);
        for (i, (a, b)) in on.0.iter().zip(&off.0).enumerate() {
            assert!(a == b, "frame {i}: cache on and off differ");
        }
        let s = atlas_stats(&last_on);
        assert_eq!(s.redrawn, s.faces, "moving lights: every face is drawn");
        assert!(on.0.windows(2).any(|w| w[0] != w[1]), "the lights should move the shadows");

        // Still lights, then the second one moved: the first keeps its faces.
        let mut still = base;
        still.frames = 1;
        still.time = Some(0.0);
        let mut moved = scene.lights.clone();
        moved[1].position_radius[0] -= 0.5;
        let still_then_moved = |r: &mut Renderer| {
            r.reconfigure(RenderSettings { omni: r.settings().omni, ..still }).expect("reconfigure");
            r.render().expect("render");
            r.set_lights(moved.clone()).expect("lights");
            r.render().expect("render")
        };
        let (a, b) = (still_then_moved(cached), still_then_moved(uncached));
        let s = atlas_stats(&a);
        println!("one light moved: {} of {} faces drawn again", s.redrawn, s.faces);
        assert!(s.redrawn > 0 && s.redrawn <= 6 && s.redrawn < s.faces, "only the moved light's faces are drawn: {s:?}");
        assert_eq!(a.rgba, b.rgba, "cache on and off differ after one light moved");
    });
}

/// Where the shadows straddle the light's face seams: a light in the room's middle and an
/// occluder on each of a few seams (between two faces, and on the corner of three).
const SEAMS: [Vec3; 5] =
    [Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, 0.0, 1.0), Vec3::new(0.0, -1.0, -1.0), Vec3::new(1.0, 1.0, 1.0), Vec3::new(-1.0, 1.0, -1.0)];

fn seam_room() -> Scene {
    let grey = Material { albedo: Vec3::splat(0.7), roughness: 0.7, metallic: 0.0 };
    let mut scene = Scene::shadow_room();
    scene.objects.truncate(1);
    for along in SEAMS {
        scene.objects.push(Object::placed(MeshKind::Sphere, along.normalize() * 2.0, 0.45, grey));
    }
    scene.lights = vec![PointLight { position_radius: [0.0, 0.0, 0.0, 20.0], color: [3.0, 3.0, 3.0, 0.0] }];
    scene
}

/// The camera inside the light's sphere, beside the light, looking along each seam at the
/// shadow that straddles it, faces sized by the screen: every pixel the ray test is sure of
/// is as it says, the shadowed ones included — a face left out of the atlas reads as lit.
#[test]
fn no_sampled_face_is_missing_with_the_camera_inside_the_light() {
    // The margin the ray test leaves is for faces of 512²; the faces here are larger (checked).
    const MARGIN_SIZE: u32 = 512;
    for along in SEAMS.map(Vec3::normalize) {
        let mut scene = seam_room();
        // Beside the light and a little behind it, off the line through the occluder.
        let side = along.cross(Vec3::Y).try_normalize().unwrap_or(Vec3::X);
        let eye = side * 1.2 - along * 0.5 + Vec3::Y * 0.2;
        scene.camera = Camera::looking_at(eye, along * 4.0, 100.0, 0.05, 50.0);
        let mut dark = scene.clone();
        dark.lights[0].color = [0.0; 4];
        // 64 MiB: the faces are halved to fit (and drawn four times faster).
        let all = [
            settings(Technique::Forward, ShadingModel::Pbr, Some((atlas(64, true, None), 1))),
            settings(Technique::Forward, ShadingModel::Pbr, None),
        ];
        let outputs = common::render_each(&scene, &all);
        let (shadowed, lit) = (&outputs[0], &outputs[1]);
        let unlit = common::render(dark, settings(Technique::Forward, ShadingModel::Pbr, None));
        let stats = atlas_stats(shadowed);
        assert!(stats.tile_bytes >= stats.faces as u64 * (MARGIN_SIZE as u64).pow(2) * 4, "faces under {MARGIN_SIZE}²: {stats:?}");
        let (mut n_lit, mut n_dark, mut wrong) = (0, 0, Vec::new());
        for ((x, y), on) in sure_pixels(&scene, SIZE, MARGIN_SIZE) {
            let want = if on[0] { lit } else { &unlit };
            *(if on[0] { &mut n_lit } else { &mut n_dark }) += 1;
            let (got, want) = (common::pixel(shadowed, x, y), common::pixel(want, x, y));
            if got.iter().zip(want).any(|(a, b)| a.abs_diff(b) > 1) {
                wrong.push(((x, y), got, want));
            }
        }
        println!("along {along}: {} faces, {n_lit} lit and {n_dark} shadowed pixels checked, {} wrong", stats.faces, wrong.len());
        assert!(
            wrong.is_empty(),
            "along {along}: pixels unlike the ray test (pixel, rendered, expected): {:?}",
            &wrong[..wrong.len().min(12)]
        );
        assert!(n_lit > 1000 && n_dark > 30, "along {along}: too few pixels checked");
    }
}

/// 2,048 shadowed lights over the room: every face they need fits half the default budget
/// (the default's share for 4,096, at lavapipe's cost for half as many faces), and what the
/// shadows take (the atlas, the tables, the raster's lists) is within it; a budget too
/// small for every face at the smallest size is an error, not a dropped shadow.
#[test]
fn shadow_memory_stays_in_the_budget_at_2048_lights() {
    const LIGHTS: u32 = 2048;
    let mut scene = Scene::shadow_room();
    let mut seed = 1u32;
    let mut next = || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    scene.lights = (0..LIGHTS)
        .map(|_| {
            let p = Vec3::new(next() * 9.0 - 4.5, next() * 9.0 - 4.5, next() * 9.0 - 4.5);
            PointLight { position_radius: [p.x, p.y, p.z, 0.5 + 2.0 * next()], color: [0.02, 0.02, 0.02, 0.0] }
        })
        .collect();
    let mut s = settings(Technique::ClusteredCpu, ShadingModel::Pbr, Some((atlas(128, true, None), LIGHTS)));
    s.width = 64;
    s.height = 64;
    let out = common::render(scene.clone(), s);
    let stats = atlas_stats(&out);
    println!(
        "{LIGHTS} lights: {} faces, side ÷{}; shadows take {:.1} of {} MiB (atlas {:.1} MiB, tiles {:.1} MiB)",
        stats.faces,
        stats.divided_by,
        stats.shadow_bytes as f64 / (1 << 20) as f64,
        stats.budget >> 20,
        stats.atlas_bytes as f64 / (1 << 20) as f64,
        stats.tile_bytes as f64 / (1 << 20) as f64
    );
    assert!(stats.shadow_bytes <= stats.budget, "{stats:?}");
    assert!(stats.tile_bytes <= stats.atlas_bytes);
    assert!(stats.faces > LIGHTS as usize, "most lights have faces in view: {}", stats.faces);

    let mut small = s;
    small.omni = Some(OmniShadowSettings { mode: atlas(8, true, None), lights: LIGHTS, all: false, size: CUBE });
    let ctx = Context::new(&ContextDesc::default()).expect("a Vulkan device");
    let err = Renderer::new(&ctx, scene, small).and_then(|mut r| r.render()).err().expect("a budget too small for every face");
    println!("8 MiB: {err}");
    assert!(err.to_string().contains("MiB"), "{err}");
}

/// A budget of 0, or of more than the device's memory, is refused with a clear error.
#[test]
fn absurd_budgets_are_refused() {
    let ctx = Context::new(&ContextDesc::default()).expect("a Vulkan device");
    for mib in [0, u32::MAX] {
        let s = settings(Technique::Forward, ShadingModel::Pbr, Some((atlas(mib, true, None), 1)));
        let err = Renderer::new(&ctx, Scene::shadow_room(), s).err().expect("an absurd budget");
        println!("{mib} MiB: {err}");
        assert!(err.to_string().contains("shadow budget"), "{err}");
    }
}

/// --debug-view shadow-atlas: the faces' depths where the plan put them, free space black.
#[test]
fn the_atlas_view_shows_the_faces() {
    let mut s = settings(Technique::Forward, ShadingModel::Pbr, Some((atlas(256, true, Some(CUBE)), 2)));
    s.debug_view = view("shadow-atlas");
    let out = common::render(two_light_room(), s);
    let black = out.rgba.chunks_exact(4).filter(|p| p[..3] == [0, 0, 0]).count();
    let total = (SIZE * SIZE) as usize;
    println!("{black} of {total} pixels black");
    assert!(black > 0 && black < total, "the view should show faces and free space");
}
