//! Point-light shadow cubes (docs/DESIGN.md#point-light-shadows) against a CPU ray test. A
//! light's contribution adds up, so at a pixel where the ray test is sure which lights see the
//! surface, the shadowed image must equal the shadow-less render of the scene with only those
//! lights switched on (the others' colour zeroed) — exactly where every PCF tap agrees, which
//! is also the "no acne, no peter-panning" check. Pixels within a few cube texels of a shadow
//! edge (or on an object's silhouette) are left out.

use crate::common;
use crate::common::view;

use glam::Vec3;
use ml_cpu::camera::Camera;
use ml_cpu::gpu_types::PointLight;
use ml_cpu::lights::LightParams;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{Object, Scene};
use ml_cpu::textures::cube_direction;
use ml_render::settings::multiview_depth_is_broken;
use ml_render::{OmniShadowMode, OmniShadowSettings, RenderOutput, RenderSettings, Renderer, ShadingModel, Technique};
use ml_vk::{Context, ContextDesc};
use std::collections::HashMap;

const CUBE: u32 = 512;

fn settings(technique: Technique, size: u32, omni: Option<(OmniShadowMode, u32)>) -> RenderSettings {
    let mut s = RenderSettings::new(technique, size, size);
    s.shading = ShadingModel::Pbr;
    s.omni = omni.map(|(mode, lights)| OmniShadowSettings { mode, lights, all: false, size: CUBE });
    s
}

/// The one-pass mode this device renders right (multiview where it works, else layered).
fn one_pass_modes() -> Vec<OmniShadowMode> {
    let ctx = Context::new(&ContextDesc::default()).expect("a Vulkan device");
    let mut modes = vec![OmniShadowMode::Layered];
    if ctx.info.features.multiview && !multiview_depth_is_broken(&ctx) {
        modes.push(OmniShadowMode::Multiview);
    }
    modes
}

/// The scene with only the lights in `on` lit (the rest black), no shadows.
fn with_lights(scene: &Scene, on: &[bool]) -> Scene {
    let mut s = scene.clone();
    for (l, &lit) in s.lights.iter_mut().zip(on) {
        if !lit {
            l.color = [0.0; 4];
        }
    }
    s
}

/// A pixel, what was rendered there and what the ray test expected.
type Disagreement = ((u32, u32), [u8; 3], [u8; 3]);

struct RayTestResult {
    /// Pixels checked where every light reaches / none does / some do.
    lit: usize,
    shadowed: usize,
    mixed: usize,
    /// Pixels checked per light pattern (which lights reach them).
    patterns: HashMap<Vec<bool>, usize>,
    /// Checked pixels further than 1/255 from the expected render.
    wrong: Vec<Disagreement>,
}

/// Render `scene` with every light shadowed (`mode`) and compare every sure pixel.
fn ray_test(scene: &Scene, size: u32, mode: OmniShadowMode) -> RayTestResult {
    let n = scene.lights.len() as u32;
    let shadowed = common::render(scene.clone(), settings(Technique::Forward, size, Some((mode, n))));
    let pixels = common::shadow_rays::sure_pixels(scene, size, CUBE);
    let mut expected: HashMap<Vec<bool>, RenderOutput> = HashMap::new();
    let mut result = RayTestResult { lit: 0, shadowed: 0, mixed: 0, patterns: HashMap::new(), wrong: Vec::new() };
    for ((x, y), on) in pixels {
        let reference =
            expected.entry(on.clone()).or_insert_with(|| common::render(with_lights(scene, &on), settings(Technique::Forward, size, None)));
        let (got, want) = (common::pixel(&shadowed, x, y), common::pixel(reference, x, y));
        if got.iter().zip(want).any(|(a, b)| a.abs_diff(b) > 1) {
            result.wrong.push(((x, y), got, want));
        }
        *result.patterns.entry(on.clone()).or_default() += 1;
        match on.iter().filter(|&&b| b).count() {
            0 => result.shadowed += 1,
            k if k == on.len() => result.lit += 1,
            _ => result.mixed += 1,
        }
    }
    result
}

fn assert_matches(what: &str, r: &RayTestResult, min_lit: usize, min_shadowed: usize) {
    println!("{what}: {} lit, {} shadowed, {} mixed pixels checked; {} wrong", r.lit, r.shadowed, r.mixed, r.wrong.len());
    assert!(
        r.wrong.is_empty(),
        "{what}: pixels that disagree with the ray test (pixel, rendered, expected): {:?}",
        &r.wrong[..r.wrong.len().min(12)]
    );
    assert!(r.lit >= min_lit && r.shadowed >= min_shadowed, "{what}: too few pixels checked");
}

/// A closed room with a pillar and a point light (the room scene, docs/scenes.md#room): the
/// pillar's shadow on the floor and walls where the ray test says, the lit walls and floor free
/// of acne, and the shadow touching the pillar's foot (no peter-panning: the margin is a few
/// texels).
#[test]
fn pillar_shadow_falls_where_the_ray_test_says() {
    let r = ray_test(&Scene::shadow_room(), 128, OmniShadowMode::Direct);
    assert_matches("room", &r, 4000, 100);
}

/// Six occluders around a light, one per cube face, each a different size and off its axis
/// (a swapped or mirrored face moves its shadow): seen wall by wall.
#[test]
fn each_face_casts_its_occluders_shadow_on_its_own_wall() {
    let light = Vec3::new(0.0, 0.0, 0.0);
    let mut scene = Scene::shadow_room();
    let grey = Material { albedo: Vec3::splat(0.7), roughness: 0.7, metallic: 0.0 };
    scene.objects.truncate(1);
    for (centre, radius) in occluders() {
        scene.objects.push(Object::placed(MeshKind::Sphere, centre, radius, grey));
    }
    scene.lights = vec![PointLight { position_radius: [light.x, light.y, light.z, 20.0], color: [3.0, 3.0, 3.0, 0.0] }];
    for (face, axis) in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z].into_iter().enumerate() {
        // From the far side of the room, off-centre, looking at the wall.
        let side = if axis.y == 0.0 { Vec3::Y } else { Vec3::X };
        let eye = -axis * 3.5 + side * 1.5 + axis.cross(side) * 1.0;
        scene.camera = Camera::looking_at(eye, axis * 5.0, 80.0, 0.05, 50.0);
        let r = ray_test(&scene, 128, OmniShadowMode::Copy);
        assert_matches(&format!("face {face} ({axis})"), &r, 2000, 40);
    }
}

/// One sphere per cube face: near each axis, shifted sideways, each its own radius.
fn occluders() -> [(Vec3, f32); 6] {
    [
        (Vec3::new(2.0, 0.5, -0.3), 0.4),
        (Vec3::new(-2.0, -0.4, 0.6), 0.5),
        (Vec3::new(0.6, 2.0, 0.2), 0.3),
        (Vec3::new(-0.3, -2.0, -0.5), 0.45),
        (Vec3::new(0.4, -0.6, 2.0), 0.35),
        (Vec3::new(-0.5, 0.3, -2.0), 0.55),
    ]
}

/// Two lights with a cube each (a cube-map array of two): every pixel's light mix as the ray
/// test says, so each light reads its own cube.
#[test]
fn two_shadowed_lights_read_their_own_cubes() {
    let mut scene = Scene::shadow_room();
    scene.lights.push(PointLight { position_radius: [3.0, -1.0, 3.5, 20.0], color: [1.0, 2.0, 3.0, 0.0] });
    let r = ray_test(&scene, 128, OmniShadowMode::Layered);
    assert_matches("two lights", &r, 1500, 0);
    for pattern in [vec![true, false], vec![false, true]] {
        let n = r.patterns.get(&pattern).copied().unwrap_or(0);
        assert!(n >= 50, "only {n} pixels where exactly the lights {pattern:?} reach");
    }
}

/// copy, direct, the one-pass modes and the compute raster fill the same cubes: the same image.
#[test]
fn every_mode_gives_the_same_image() {
    let scene = Scene::shadow_room();
    let mut modes = vec![OmniShadowMode::Copy, OmniShadowMode::Direct];
    modes.extend(one_pass_modes());
    modes.push(OmniShadowMode::COMPUTE);
    let all: Vec<RenderSettings> = modes.iter().map(|&m| settings(Technique::Forward, 96, Some((m, 1)))).collect();
    let outputs = common::render_each(&scene, &all);
    for (mode, out) in modes.iter().zip(&outputs).skip(1) {
        let (max, differing) = common::max_difference(&outputs[0], out);
        println!("{} vs copy: max {max}/255, {differing} pixels differ", mode.name());
        assert!(max <= 1, "{} differs from copy by {max}/255", mode.name());
    }
}

/// Every technique shades with the cubes: each equals forward (deferred paths rebuild the
/// position from depth, which moves a PCF tap by a hair: ≤ 2/255).
#[test]
fn every_technique_casts_the_same_shadows() {
    let scene = Scene::shadow_room();
    let all: Vec<RenderSettings> = Technique::ALL.iter().map(|&t| settings(t, 128, Some((OmniShadowMode::Direct, 1)))).collect();
    let outputs = common::render_each(&scene, &all);
    for (t, out) in Technique::ALL.iter().zip(&outputs).skip(1) {
        let (max, differing) = common::max_difference(&outputs[0], out);
        println!("{} vs forward: max {max}/255, {differing} pixels differ", t.name());
        assert!(max <= 2, "{} differs from forward by {max}/255", t.name());
    }
    // And the shadow is there: the shadowed image is not the shadow-less one.
    let plain = common::render(scene, settings(Technique::Forward, 128, None));
    let darker = common::pixels_beyond(&outputs[0], &plain, 20);
    assert!(darker > 100, "only {darker} pixels in shadow");
}

/// --debug-view shadow-cube: the six faces of the first shadowed light as a cross, each face
/// as its texels lie: at each face's centre the wall 5 m away (grey 1 − 5/20), and at the
/// texel Vulkan's cube sampling reads for an occluder's centre, that occluder's near side.
#[test]
fn shadow_cube_view_shows_each_face_in_its_cell() {
    const SIZE: u32 = 64;
    let mut scene = Scene::shadow_room();
    let grey = Material { albedo: Vec3::splat(0.7), roughness: 0.7, metallic: 0.0 };
    scene.objects.truncate(1);
    for (centre, radius) in occluders() {
        scene.objects.push(Object::placed(MeshKind::Sphere, centre, radius, grey));
    }
    scene.lights = vec![PointLight { position_radius: [0.0, 0.0, 0.0, 20.0], color: [3.0, 3.0, 3.0, 0.0] }];
    let (width, height) = (4 * SIZE, 3 * SIZE);
    let mut s = RenderSettings::new(Technique::Forward, width, height);
    s.omni = Some(OmniShadowSettings { mode: OmniShadowMode::Layered, lights: 1, all: false, size: SIZE });
    s.debug_view = view("shadow-cube");
    let out = common::render(scene, s);
    let cells = [(2, 1), (0, 1), (1, 0), (1, 2), (1, 1), (3, 1)];
    let grey_at = |face: usize, tx: u32, ty: u32| {
        let (cx, cy) = cells[face];
        common::pixel(&out, cx * SIZE + tx, cy * SIZE + ty)[0] as f32 / 255.0
    };
    for (face, &(centre, radius)) in occluders().iter().enumerate() {
        let wall = grey_at(face, SIZE / 2, SIZE / 2);
        assert!((wall - 0.75).abs() < 0.02, "face {face}: centre {wall}, expected the wall at 0.75");
        // The texel whose direction is nearest the occluder's centre.
        let (tx, ty) = (0..SIZE * SIZE)
            .map(|i| (i % SIZE, i / SIZE))
            .max_by(|a, b| {
                let along = |t: &(u32, u32)| cube_direction(face as u32, t.0, t.1, SIZE).normalize().dot(centre.normalize());
                along(a).total_cmp(&along(b))
            })
            .unwrap();
        let near = grey_at(face, tx, ty);
        let expected = 1.0 - (centre.length() - radius) / 20.0;
        assert!((near - expected).abs() < 0.02, "face {face}: occluder texel ({tx}, {ty}) shows {near}, expected {expected}");
    }
    // Outside the cross: black.
    assert_eq!(common::pixel(&out, 0, 0), [0, 0, 0]);
    assert_eq!(common::pixel(&out, width - 1, height - 1), [0, 0, 0]);
}

/// What a render left in the shadow cubes, with its image.
fn cubes_and_image(ctx: &Context, scene: &Scene, settings: RenderSettings) -> (Vec<f32>, RenderOutput) {
    let mut renderer = Renderer::new(ctx, scene.clone(), settings).expect("renderer");
    let image = renderer.render().expect("render");
    (renderer.shadow_cube_depths().expect("cube read-back"), image)
}

/// The compute raster (--omni-shadow compute) fills the cubes the graphics modes fill, texel
/// by texel: on the room (large triangles — walls and floor cross several faces, corners
/// reach past the face's far plane), the seed scene (49 spheres: small triangles, a thread
/// each) and a light inside an occluder's reach (triangles crossing the faces' near plane,
/// which the compute raster clips), also with the list of large triangles full: every texel
/// covered by both or neither, the distances
/// equal up to interpolation rounding. Its images equal the layered mode's.
#[test]
fn the_compute_raster_fills_the_same_cubes() {
    let ctx = Context::new(&ContextDesc { validation: true, ..Default::default() }).expect("a validated Vulkan device");
    let counter = ctx.validation_counter();
    let mut near = Scene::shadow_room();
    // A box corner a hair from the light: its faces cross the cube faces' near plane.
    let light = Vec3::from_slice(&near.lights[0].position_radius[..3]);
    let grey = Material { albedo: Vec3::splat(0.7), roughness: 0.7, metallic: 0.0 };
    near.objects.push(Object::placed(MeshKind::Cube, light + Vec3::new(0.25, 0.25, 0.25), 0.25, grey));
    let seed = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap();
    // The list of large triangles also full at once (every one drawn by the thread that
    // found it), and after 100.
    let compute = OmniShadowMode::COMPUTE;
    let in_place = |large_list| OmniShadowMode::Compute { large_list };
    let room = Scene::shadow_room();
    for (name, scene, lights, cube, compute) in [
        ("room", &room, 1, 128, compute),
        ("room, list of 100", &room, 1, 128, in_place(100)),
        ("near plane", &near, 1, 64, compute),
        ("near plane, no list", &near, 1, 64, in_place(0)),
        ("seed", &seed, 2, 64, compute),
    ] {
        let mut s = RenderSettings::new(Technique::Forward, 96, 96);
        s.shading = ShadingModel::Pbr;
        let mode = |mode| Some(OmniShadowSettings { mode, lights, all: false, size: cube });
        s.omni = mode(OmniShadowMode::Layered);
        let (hardware, hardware_image) = cubes_and_image(&ctx, scene, s);
        s.omni = mode(compute);
        let (compute, compute_image) = cubes_and_image(&ctx, scene, s);
        let (coverage, differ) = common::coverage_difference(&hardware, &compute);
        let reached = common::reached;
        let worst = hardware.iter().zip(&compute).map(|(h, c)| (h - c).abs()).fold(0.0, f32::max);
        // In units of the shading's depth bias at that texel (one texel of distance).
        let bias = |d: f32| d * 2.0 / cube as f32;
        let worst_in_bias =
            hardware.iter().zip(&compute).filter(|(h, _)| reached(**h)).map(|(h, c)| (h - c).abs() / bias(*h)).fold(0.0, f32::max);
        let surfaces = hardware.iter().filter(|&&d| reached(d)).count();
        let (max, pixels) = common::max_difference(&hardware_image, &compute_image);
        println!(
            "{name}: {surfaces} of {} texels hold a surface, {} covered by one raster only; {differ} differ, by at most {worst:e} radii ({worst_in_bias:.4} of the depth bias); images: max {max}/255 at {pixels} pixels",
            hardware.len(),
            coverage.len()
        );
        assert!(surfaces > 4000, "{name}: only {surfaces} texels hold a surface");
        assert!(
            coverage.is_empty(),
            "{name}: texels (index, hardware, compute) one raster covers: {:?}",
            &coverage[..coverage.len().min(12)]
        );
        // Drivers interpolate the fragment shader's input their own way (lavapipe: a plane
        // equation from the unsnapped corners; we: the snapped corners' edge functions, as
        // the coverage): distances agree to a few units in the last place, more on slivers,
        // always far below the depth bias the shading compares with.
        assert!(worst_in_bias <= 0.125, "{name}: depths differ by up to {worst_in_bias} of the depth bias");
        assert!(max <= 1, "{name}: images differ by {max}/255");
    }
    drop(ctx);
    assert_eq!(counter.load(std::sync::atomic::Ordering::SeqCst), 0, "validation messages (printed above)");
}
