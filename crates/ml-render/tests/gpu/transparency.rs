//! Transparency (glTF `alphaMode: BLEND`): transparent surfaces lit by the same lights as the
//! opaque ones and blended back to front per pixel, in every technique.
//!
//! - three overlapping coloured glass quads in front of a lit wall, under point lights: every
//!   technique's image equals a CPU reference — each surface the pixel's ray meets shaded by
//!   the seed model's CPU reference (`shade_seed`), the glass layers blended over the wall by
//!   `ml_cpu::transparency::composite` — within 2/255, but at counted edge pixels (where the
//!   ray of a neighbouring pixel meets another set of surfaces);
//! - the order in which the quads are listed does not change a byte (all six orders);
//! - a budget smaller than the depth complexity drops fragments and says how many; more
//!   layers than a pixel blends exactly are merged and counted;
//! - foliage: leaves (quads of a glTF file written here, BLEND, double-sided, a texture whose
//!   alpha is 0 in a round hole, 1 in a ring round it and fades to 0 over soft bands on both
//!   sides) over a lit floor: every technique gives forward's image within 1/255 but at
//!   counted edge pixels; the hole shows exactly what the scene without the leaves shows, and
//!   the soft bands blend: their pixels lie between the leafless image and the one with the
//!   leaves opaque;
//! - the transparency-layers debug view counts each pixel's layers;
//! - the build over tiles and the build a thread per triangle leave the same fragments: an
//!   object moved from one to the other changes no byte — test foliage, panes, and the forest
//!   the benchmarks render (`ml_cpu::forest`, BLEND leaves), small.

use crate::common;
use crate::common::view;

use glam::{Mat4, Quat, Vec3, Vec4};
use ml_cpu::camera::Camera;
use ml_cpu::gltf_writer::{png, quad as gltf_quad, GltfWriter, PrimitiveData};
use ml_cpu::gpu_types::PointLight;
use ml_cpu::material::Material;
use ml_cpu::material_lobes::{lobed_transmittance, shade_lobed, MaterialLobes};
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{AlphaMode, Object, Scene};
use ml_cpu::shading::{aces_tone_map, encode_gamma_unorm8, shade_seed};
use ml_cpu::transparency::{composite, Layer};
use ml_render::{
    Antialiasing, CullStats, Raster, RenderOutput, RenderSettings, Renderer, ShadingModel, Technique, TransparencySettings,
    TransparencyStats, DEFAULT_CANDIDATE_LIST, LAYER_KEEP,
};
use serde_json::json;

const W: u32 = 160;
const H: u32 = 120;
/// Allowed difference from the reference, in 8-bit steps.
const MAX_DIFF: u8 = 2;
/// Most edge pixels an image may have beyond the tolerance (quad borders: a pixel whose
/// neighbour's ray meets another set of surfaces).
const MAX_EDGE_PIXELS: usize = 400;

/// A quad facing +Z (the camera): the plane mesh (±1 in x and z, normal +Y) stood up, centred
/// at `at`, `half` to each side.
fn quad(at: Vec3, half: (f32, f32), albedo: [f32; 3], alpha: Option<f32>) -> Object {
    let rotation = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let mut o = Object::placed(MeshKind::Plane, Vec3::ZERO, 1.0, Material { albedo: Vec3::from(albedo), roughness: 0.6, metallic: 0.0 });
    o.transform = Mat4::from_scale_rotation_translation(Vec3::new(half.0, 1.0, half.1), rotation, at);
    if let Some(a) = alpha {
        o.extras.alpha_mode = AlphaMode::Blend;
        o.extras.base_alpha = a;
    }
    o
}

fn light(p: [f32; 3], radius: f32, c: [f32; 3]) -> PointLight {
    PointLight { position_radius: [p[0], p[1], p[2], radius], color: [c[0], c[1], c[2], 0.0] }
}

/// The three glass quads (red, green, blue; alpha 0.5, 0.4, 0.6), overlapping in the middle.
fn glass() -> [Object; 3] {
    [
        quad(Vec3::new(-0.5, 0.3, 0.9), (1.0, 0.8), [0.9, 0.15, 0.1], Some(0.5)),
        quad(Vec3::new(0.45, 0.2, 0.6), (0.9, 1.0), [0.1, 0.85, 0.2], Some(0.4)),
        quad(Vec3::new(0.0, -0.45, 0.3), (1.2, 0.7), [0.15, 0.2, 0.95], Some(0.6)),
    ]
}

/// The wall at z = 0 behind them, filling the view, then the glass in `order`, lit by
/// four lights in front (one of them crossing the glass).
fn scene(order: [usize; 3]) -> Scene {
    let panes = glass();
    let mut objects = vec![quad(Vec3::ZERO, (6.0, 6.0), [0.8, 0.75, 0.7], None)];
    objects.extend(order.iter().map(|&i| panes[i]));
    let lights = vec![
        light([1.5, 1.2, 2.0], 5.0, [1.0, 0.9, 0.8]),
        light([-1.8, -0.6, 1.6], 4.0, [0.6, 0.7, 1.0]),
        light([0.2, 0.1, 0.7], 1.5, [1.0, 0.6, 0.3]),
        light([0.0, -1.5, 3.0], 5.0, [0.5, 0.5, 0.5]),
    ];
    let camera = Camera::looking_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 50.0, 0.1, 20.0);
    let mut s = Scene::new(objects, lights, camera);
    s.light_motion = 0.0;
    s
}

/// Where the ray (o, d) meets the quad `q` (facing +Z): the distance along it.
fn hit(q: &Object, (o, d): (Vec3, Vec3)) -> Option<f32> {
    let at = q.position();
    let half = (q.transform.x_axis.length(), q.transform.z_axis.length());
    let t = (at.z - o.z) / d.z;
    let p = o + d * t;
    (t > 0.0 && (p.x - at.x).abs() <= half.0 && (p.y - at.y).abs() <= half.1).then_some(t)
}

/// The surfaces a pixel's ray meets: the objects' indices.
fn met(scene: &Scene, x: u32, y: u32) -> Vec<usize> {
    let ray = scene.camera.pixel_ray(x, y, W, H);
    (0..scene.objects.len()).filter(|&i| hit(&scene.objects[i], ray).is_some()).collect()
}

/// The CPU reference image: each surface the ray meets shaded in the seed model, the glass
/// blended over the wall.
fn reference(scene: &Scene) -> Vec<[u8; 3]> {
    let eye = scene.camera.position;
    reference_with(scene, |o, p| (shade_seed(p, Vec3::Z, eye, &o.material, &scene.lights, scene.ambient), Vec3::ZERO), encode_gamma_unorm8)
}

/// The CPU reference image: each surface the ray meets shaded by `shade` (its light and what
/// it lets through at a point), the layers blended over the wall (every one a layer but the
/// first object), encoded by `encode`.
fn reference_with(scene: &Scene, shade: impl Fn(&Object, Vec3) -> (Vec3, Vec3), encode: impl Fn(Vec3) -> [u8; 3]) -> Vec<[u8; 3]> {
    let mut out = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let ray = scene.camera.pixel_ray(x, y, W, H);
            let wall = &scene.objects[0];
            let under = hit(wall, ray).map(|t| shade(wall, ray.0 + ray.1 * t).0).expect("the wall fills the view");
            let layers: Vec<Layer> = (1..scene.objects.len())
                .filter_map(|i| {
                    let o = &scene.objects[i];
                    let alpha = if o.extras.alpha_mode == AlphaMode::Blend { o.extras.base_alpha } else { 1.0 };
                    hit(o, ray).map(|t| {
                        let (color, transmitted) = shade(o, ray.0 + ray.1 * t);
                        Layer { depth: t, id: i as u32, color, alpha, transmitted }
                    })
                })
                .collect();
            out.push(encode(composite(under, &layers, LAYER_KEEP as usize).color));
        }
    }
    out
}

/// How many pixels of `out` differ from `want` by more than MAX_DIFF — each must be an edge
/// pixel — and by how much the others differ at most.
fn edge_differences(scene: &Scene, out: &RenderOutput, want: &[[u8; 3]], s: &RenderSettings) -> (usize, u8) {
    let (mut edges, mut worst) = (0, 0u8);
    for y in 0..H {
        for x in 0..W {
            let (got, w) = (common::pixel(out, x, y), want[(y * W + x) as usize]);
            let d = diff(got, w);
            if d > MAX_DIFF {
                let (technique, raster) = (s.technique.name(), s.raster.name());
                assert!(edge(scene, x, y), "{technique} ({raster}): pixel ({x}, {y}) is {got:?}, the CPU reference {w:?}");
                edges += 1;
            } else {
                worst = worst.max(d);
            }
        }
    }
    (edges, worst)
}

/// Whether pixel (x, y)'s neighbours' rays meet other surfaces than its own.
fn edge(scene: &Scene, x: u32, y: u32) -> bool {
    let own = met(scene, x, y);
    (-1i32..=1).any(|dy| {
        (-1i32..=1).any(|dx| {
            let (nx, ny) = (x as i32 + dx, y as i32 + dy);
            (0..W as i32).contains(&nx) && (0..H as i32).contains(&ny) && met(scene, nx as u32, ny as u32) != own
        })
    })
}

fn settings(technique: Technique) -> RenderSettings {
    let mut s = RenderSettings::new(technique, W, H);
    s.transparency = Some(TransparencySettings::default());
    if technique == Technique::Visibility {
        s.raster = Raster::compute(Raster::DEFAULT_SPLIT);
    }
    s
}

fn stats(out: &RenderOutput) -> TransparencyStats {
    *out.stats.feature::<TransparencyStats>().expect("the layers' figures")
}

#[test]
fn glass_over_a_wall_equals_the_cpu_blend_in_every_technique() {
    let scene = scene([0, 1, 2]);
    let want = reference(&scene);
    let mut all: Vec<RenderSettings> = Technique::ALL.iter().map(|&t| settings(t)).collect();
    all.push(RenderSettings { raster: Raster::Hardware, ..settings(Technique::Visibility) });
    let outs = common::render_each(&scene, &all);
    for (s, out) in all.iter().zip(&outs) {
        let (edges, worst) = edge_differences(&scene, out, &want, s);
        assert!(edges <= MAX_EDGE_PIXELS, "{}: {edges} edge pixels differ", s.technique.name());
        let st = stats(out);
        assert!(!st.overflowed(), "{}: {st:?}", s.technique.name());
        assert!(st.fragments > (W * H / 2) as u64, "{}: only {} transparent fragments", s.technique.name(), st.fragments);
        println!(
            "{} ({}): {edges} edge pixels beyond {MAX_DIFF}/255, others within {worst}/255; {st:?}",
            s.technique.name(),
            s.raster.name()
        );
    }
}

/// The wall and three panes in the pbr model: a transmitting one (OPAQUE, tinted by a volume),
/// a half-covering transmitting one (BLEND) and a plain BLEND one, overlapping in the middle.
fn transmitting_glass() -> Scene {
    let mut scene = scene([0, 1, 2]);
    let [a, b, c] = &mut scene.objects[1..] else { unreachable!() };
    a.material = Material { albedo: Vec3::new(0.95, 0.6, 0.3), roughness: 0.3, metallic: 0.0 };
    a.extras.alpha_mode = AlphaMode::Opaque;
    a.extras.base_alpha = 0.2; // ignored: OPAQUE
    a.extras.lobes = MaterialLobes {
        transmission: 1.0,
        attenuation_color: Vec3::new(0.6, 0.9, 1.0),
        attenuation_distance: 0.4,
        thickness: 0.2,
        ..Default::default()
    };
    b.material.roughness = 0.45;
    b.extras.lobes = MaterialLobes { transmission: 0.8, ior: 1.7, ..Default::default() };
    c.extras.base_alpha = 0.35;
    scene
}

#[test]
fn transmitting_glass_tints_what_lies_behind_as_the_cpu_reference_does() {
    // Each pane's light (its diffuse share given to transmission) and what it lets through
    // (base colour × (1 − Fresnel) × the volume's transmittance) per pixel, as
    // ml_cpu::material_lobes has them; blended by ml_cpu::transparency's rule.
    let scene = transmitting_glass();
    let eye = scene.camera.position;
    let want = reference_with(
        &scene,
        |o, p| {
            let lobes = (&o.material, &o.extras.lobes);
            let lit = shade_lobed(p, (Vec3::Z, Vec3::Z), eye, lobes, &scene.lights, scene.ambient, Vec3::ZERO);
            let n_dot_v = (eye - p).normalize().z;
            (lit, lobed_transmittance((n_dot_v, n_dot_v), &o.material, &o.extras.lobes))
        },
        |c| encode_gamma_unorm8(aces_tone_map(c)),
    );
    let pbr = |s: RenderSettings| RenderSettings { shading: ShadingModel::Pbr, ..s };
    let mut all: Vec<RenderSettings> =
        [Technique::Forward, Technique::ClusteredGpu, Technique::Visibility].map(|t| pbr(settings(t))).into();
    all.push(RenderSettings { antialiasing: Antialiasing::X8, ..all[2] });
    let outs = common::render_each(&scene, &all);
    // Without transmission the panes hide the wall: the test sees what the tint does.
    let mut opaque = scene.clone();
    opaque.objects[1].extras.lobes.transmission = 0.0;
    opaque.objects[2].extras.lobes.transmission = 0.0;
    let hidden = common::render(opaque, all[0]);
    let (mut tinted, mut checked) = (0, 0);
    for (s, out) in all.iter().zip(&outs) {
        let (edges, worst) = edge_differences(&scene, out, &want, s);
        if s.technique == Technique::Forward {
            for (x, y) in (0..H).flat_map(|y| (0..W).map(move |x| (x, y))).filter(|&(x, y)| met(&scene, x, y).contains(&1)) {
                checked += 1;
                tinted += usize::from(diff(common::pixel(out, x, y), common::pixel(&hidden, x, y)) > 8);
            }
        }
        // With samples every pixel at a pane's border is a mean over its surfaces (each of them
        // is an edge pixel, checked above); without, only some may differ.
        assert!(s.antialiasing != Antialiasing::Off || edges <= MAX_EDGE_PIXELS, "{}: {edges} edge pixels differ", s.technique.name());
        println!(
            "{} ({}, {:?}): {edges} edge pixels beyond {MAX_DIFF}/255, others within {worst}/255",
            s.technique.name(),
            s.raster.name(),
            s.antialiasing
        );
    }
    println!("{tinted} of {checked} pixels of the volume-tinted pane differ from it with no transmission");
    assert!(checked > 2_000 && tinted * 10 > checked * 9, "the wall shows through the transmitting pane: {tinted} of {checked}");
}

#[test]
fn the_order_the_quads_are_listed_in_changes_nothing() {
    let orders = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
    for technique in [Technique::Forward, Technique::DeferredCompute, Technique::Visibility] {
        let outs: Vec<RenderOutput> = orders.iter().map(|&o| common::render(scene(o), settings(technique))).collect();
        for (o, out) in orders.iter().zip(&outs).skip(1) {
            assert!(out.rgba == outs[0].rgba, "{}: the order {o:?} gives another image", technique.name());
        }
    }
}

#[test]
fn a_resized_renderer_draws_the_layers_as_a_fresh_one_does() {
    // The lists are the build pass's own buffers of each frame slot, made again for the new
    // size when the viewer resizes.
    let ctx = common::pooled_context();
    for technique in [Technique::Forward, Technique::Visibility] {
        let small = RenderSettings { frames: 2, ..settings(technique) };
        let large = RenderSettings { width: W + 24, height: H + 16, ..small };
        let mut live = Renderer::new(&ctx, scene([0, 1, 2]), small).expect("renderer");
        live.render().expect("render");
        assert!(live.reconfigure(large).expect("resize"), "a new size keeps the passes");
        let resized = live.render().expect("render after the resize");
        drop(live);
        let fresh = Renderer::new(&ctx, scene([0, 1, 2]), large).and_then(|mut r| r.render()).expect("fresh render");
        assert_eq!((resized.width, resized.height), (W + 24, H + 16));
        assert!(resized.rgba == fresh.rgba, "{}: the resized renderer's layers differ from a fresh one's", technique.name());
        assert_eq!(stats(&resized), stats(&fresh), "{}", technique.name());
    }
}

#[test]
fn a_budget_below_the_depth_complexity_is_reported() {
    // 40 faint panes one behind another over a third of the image, listed out of depth order
    // (each in its own colour and coverage): more layers than a pixel blends exactly —
    // merged beyond the nearest 32 as the CPU rule merges them — and more fragments than a
    // budget of one node per pixel holds (dropped).
    let mut deep = scene([0, 1, 2]);
    deep.objects.truncate(1);
    for k in 0..40 {
        let i = (k * 17) % 40;
        let c = [0.2 + 0.02 * i as f32, 0.9 - 0.02 * i as f32, 0.3 + 0.3 * (i % 3) as f32];
        deep.objects.push(quad(Vec3::new(0.0, 0.0, 0.05 + 0.05 * i as f32), (0.8, 0.8), c, Some(0.05 + 0.004 * i as f32)));
    }
    let mut s = settings(Technique::DeferredCompute);
    s.transparency = Some(TransparencySettings { budget: 1, ..Default::default() });
    let st = stats(&common::render(deep.clone(), s));
    assert!(st.dropped() > 0 && st.overflowed(), "{st:?}");
    assert_eq!(st.capacity, (W * H) as u64);
    let mut s = settings(Technique::Visibility);
    s.transparency = Some(TransparencySettings { budget: 16, ..Default::default() });
    let out = common::render(deep.clone(), s);
    let st = stats(&out);
    assert_eq!(st.dropped(), 0, "{st:?}");
    assert!(st.merged_pixels > 100, "{st:?}");
    let (edges, _) = edge_differences(&deep, &out, &reference(&deep), &s);
    assert!(edges <= MAX_EDGE_PIXELS, "{edges} edge pixels differ");
}

// ---------------------------------------------------------------------------------------------
// Foliage
// ---------------------------------------------------------------------------------------------

const LEAF_TEXELS: u32 = 64;

/// The leaf's alpha at texture coordinate distance `r` from its centre (in texels of a
/// 64-texel side): a hole to 9, rising to 1 by 13, 1 to 24, fading to 0 by 31.
fn leaf_alpha(r: f32) -> f32 {
    ((r - 9.0) / 4.0).clamp(0.0, 1.0) * ((31.0 - r) / 7.0).clamp(0.0, 1.0)
}

pub fn leaf_png() -> Vec<u8> {
    let n = LEAF_TEXELS;
    let rgba: Vec<u8> = (0..n * n)
        .flat_map(|i| {
            let (x, y) = ((i % n) as f32 + 0.5 - n as f32 / 2.0, (i / n) as f32 + 0.5 - n as f32 / 2.0);
            [255, 255, 255, (leaf_alpha((x * x + y * y).sqrt()) * 255.0).round() as u8]
        })
        .collect();
    png(n, n, &rgba)
}

/// Leaf i's place: standing, facing the camera (on +Z), turned a little, one behind another.
fn leaf_at(i: usize) -> (Vec3, Quat) {
    let at = Vec3::new(-1.6 + 1.1 * i as f32, 1.2 + 0.25 * (i % 2) as f32, 0.6 - 0.5 * i as f32);
    (at, Quat::from_rotation_y((10.0 * i as f32 - 15.0).to_radians()) * Quat::from_rotation_x(std::f32::consts::FRAC_PI_2))
}

const LEAVES: usize = 4;

/// A lit floor and LEAVES leaves of `mode` ("BLEND", or "OPAQUE" for their colour without
/// alpha; None: no leaves), loaded from a GLB written here.
fn foliage(mode: Option<&str>) -> Scene {
    foliage_of(mode, gltf_quad())
}

/// The quad as a grid of 12×12 cells (288 triangles, more than the tiles' build takes: built
/// a thread per triangle).
fn fine_quad() -> PrimitiveData {
    let n = 12u32;
    let at = |i: u32| i as f32 / n as f32;
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push([at(i) * 2.0 - 1.0, 0.0, at(j) * 2.0 - 1.0]);
            uvs.push([at(i), at(j)]);
        }
    }
    let v = |i: u32, j: u32| j * (n + 1) + i;
    let indices = (0..n)
        .flat_map(|j| (0..n).flat_map(move |i| [v(i, j), v(i, j + 1), v(i + 1, j), v(i + 1, j), v(i, j + 1), v(i + 1, j + 1)]))
        .collect();
    PrimitiveData {
        normals: Some(vec![[0.0, 1.0, 0.0]; positions.len()]),
        positions,
        uvs: Some(uvs),
        indices: Some((indices, ml_cpu::gltf_writer::IndexType::U32)),
        material: None,
    }
}

fn foliage_of(mode: Option<&str>, leaf: PrimitiveData) -> Scene {
    let mut w = GltfWriter::new();
    let floor = w.material([0.6, 0.55, 0.5, 1.0], 0.0, 0.8);
    let floor_mesh = w.mesh(&[PrimitiveData { material: Some(floor), ..gltf_quad() }]);
    w.node(json!({ "mesh": floor_mesh, "scale": [6.0, 6.0, 6.0] }), true);
    // A back wall, so that every pixel has an opaque surface or the leaves' colour behind.
    let upright = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2).to_array();
    w.node(json!({ "mesh": floor_mesh, "translation": [0.0, 3.0, -3.0], "rotation": upright, "scale": [6.0, 6.0, 6.0] }), true);
    if let Some(mode) = mode {
        // The same leaf as two textures: leaves of two texture sets (the compute build
        // dispatches once per set).
        let textures = [w.texture(leaf_png(), "image/png"), w.texture(leaf_png(), "image/png")];
        let colours = [[0.3, 0.8, 0.2, 1.0], [0.5, 0.9, 0.1, 0.9], [0.2, 0.6, 0.3, 1.0], [0.7, 0.8, 0.2, 0.8]];
        for (i, c) in colours.iter().enumerate().take(LEAVES) {
            let m = w.alpha_material(Some(textures[i % 2]), *c, mode, None, true);
            let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..leaf.clone() }]);
            let (at, rotation) = leaf_at(i);
            w.node(json!({ "mesh": mesh, "translation": at.to_array(), "rotation": rotation.to_array(), "scale": [0.8, 0.8, 0.8] }), true);
        }
    }
    let (mut scene, _) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    scene.camera = Camera::looking_at(Vec3::new(0.3, 2.2, 5.0), Vec3::new(0.0, 1.1, 0.0), 45.0, 0.1, 30.0);
    scene.lights = vec![
        light([1.0, 2.0, 2.5], 6.0, [4.0, 3.6, 3.2]),
        light([-2.0, 1.5, 2.0], 5.0, [2.0, 2.4, 4.0]),
        light([0.5, 0.6, -0.8], 3.0, [4.0, 2.8, 1.6]),
        light([0.0, 3.0, -2.0], 5.0, [2.4, 2.4, 2.4]),
    ];
    scene.cones.clear();
    scene.light_motion = 0.0;
    scene
}

/// Where a world point lands in the image (pixel coordinates).
fn project(scene: &Scene, p: Vec3) -> (u32, u32) {
    let clip = scene.camera.projection(W as f32 / H as f32) * scene.camera.view() * Vec4::from((p, 1.0));
    let ndc = clip.truncate() / clip.w;
    (((ndc.x + 1.0) * 0.5 * W as f32) as u32, ((ndc.y + 1.0) * 0.5 * H as f32) as u32)
}

fn diff(a: [u8; 3], b: [u8; 3]) -> u8 {
    (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap()
}

#[test]
fn foliage_shows_the_background_through_its_holes_and_blends_its_soft_edges_alike_in_every_technique() {
    let scene = foliage(Some("BLEND"));
    assert!(scene.has_transparent_objects());
    let pbr = |t| RenderSettings { shading: ShadingModel::Pbr, ..settings(t) };
    let mut all: Vec<RenderSettings> = Technique::ALL.iter().map(|&t| pbr(t)).collect();
    all.push(RenderSettings { raster: Raster::Hardware, ..pbr(Technique::Visibility) });
    let outs = common::render_each(&scene, &all);
    let forward = &outs[0];
    for (s, out) in all.iter().zip(&outs).skip(1) {
        let edges = common::pixels_beyond(forward, out, 1);
        assert!(
            edges <= (W * H / 100) as usize,
            "{} ({}): {edges} pixels differ from forward by more than 1/255",
            s.technique.name(),
            s.raster.name()
        );
        println!("{} ({}): {edges} edge pixels beyond 1/255 of forward", s.technique.name(), s.raster.name());
    }
    let bare = common::render(foliage(None), pbr(Technique::Forward));
    let mut opaque = pbr(Technique::Forward);
    opaque.transparency = None;
    let opaque = common::render(foliage(Some("OPAQUE")), opaque);
    // Through each leaf's hole: the scene without leaves.
    for i in 0..LEAVES {
        let (x, y) = project(&scene, leaf_at(i).0);
        for out in &outs {
            let (got, want) = (common::pixel(out, x, y), common::pixel(&bare, x, y));
            assert!(diff(got, want) <= 1, "leaf {i}'s hole at ({x}, {y}): {got:?}, without leaves {want:?}");
        }
        assert!(diff(common::pixel(&opaque, x, y), common::pixel(&bare, x, y)) > 8, "leaf {i}: the opaque leaf covers its hole");
    }
    // The soft bands: between the leafless and the opaque-leaf images, apart from both.
    let between = (0..H)
        .flat_map(|y| (0..W).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let (g, b, o) = (common::pixel(forward, x, y), common::pixel(&bare, x, y), common::pixel(&opaque, x, y));
            diff(g, b) >= 4 && diff(g, o) >= 4 && (0..3).all(|c| g[c].clamp(b[c].min(o[c]), b[c].max(o[c])) == g[c])
        })
        .count();
    assert!(between > 300, "only {between} pixels blend the leaves' soft edges");
    println!("{between} pixels blend a soft edge");
}

#[test]
fn the_layer_view_counts_each_pixels_layers() {
    let mut s = settings(Technique::Visibility);
    s.debug_view = view("transparency-layers");
    let scene = scene([0, 1, 2]);
    let out = common::render(scene.clone(), s);
    // No layer: black; more layers: hotter colours, never black.
    for y in (0..H).step_by(7) {
        for x in (0..W).step_by(7) {
            let layers = met(&scene, x, y).len() - 1;
            let got = common::pixel(&out, x, y);
            if edge(&scene, x, y) {
                continue;
            }
            assert_eq!(got == [0, 0, 0], layers == 0, "({x}, {y}) with {layers} layers shows {got:?}");
        }
    }
}

/// Both builds (over tiles; a thread per triangle, with its work group and tile lists of
/// larger triangles) give the same fragments bit for bit: each object moved to the other
/// build leaves every byte of the image and the fragment count unchanged — the coarse leaves'
/// large triangles through the per-triangle build's lists, the fine leaves' small triangles
/// over tiles. And the leaves as two triangles each or as 288 give the same image but at
/// edge pixels and where the two pick texture levels apart.
#[test]
fn the_tiles_build_and_the_per_triangle_build_agree() {
    let pbr = |t, tiled_up_to| {
        let mut s = RenderSettings { shading: ShadingModel::Pbr, ..settings(t) };
        s.transparency = Some(TransparencySettings { tiled_up_to, ..TransparencySettings::default() });
        s
    };
    let default = TransparencySettings::default().tiled_up_to;
    for technique in [Technique::Forward, Technique::Visibility] {
        let leaves = foliage(Some("BLEND"));
        assert_eq!(leaves.textures.len(), 2, "leaves of two texture sets");
        let coarse = common::render_each(&leaves, &[pbr(technique, default), pbr(technique, 0)]);
        let fine_leaves = foliage_of(Some("BLEND"), fine_quad());
        let fine = common::render_each(&fine_leaves, &[pbr(technique, default), pbr(technique, u32::MAX)]);
        // Panes of glass close up: triangles larger than a work group walks, and reaching
        // behind the eye, listed for the tiles.
        let mut glass = scene([0, 1, 2]);
        glass.camera = Camera::looking_at(Vec3::new(0.3, 0.2, 0.9), Vec3::new(0.0, 0.0, 0.5), 70.0, 0.1, 20.0);
        // (Wider than a work group walks: GROUP_BOX, 256 pixels.)
        let wide = |tiled_up_to| RenderSettings { width: 272, height: 160, ..pbr(technique, tiled_up_to) };
        let panes = common::render_each(&glass, &[wide(u32::MAX), wide(0)]);
        for (what, [a, b]) in
            [("coarse leaves", &coarse[..]), ("fine leaves", &fine[..]), ("panes", &panes[..])].map(|(w, o)| (w, [&o[0], &o[1]]))
        {
            println!("{} {what}: {} fragments, {} pixels differ", technique.name(), stats(a).fragments, common::pixels_beyond(a, b, 0));
            assert_eq!(stats(a).fragments, stats(b).fragments, "{} {what}", technique.name());
            assert!(a.rgba == b.rgba, "{} {what}: the builds' images differ", technique.name());
        }
        // Each kind of triangle went where the test means it to: the coarse leaves' to work
        // groups, the close panes' to the tiles, the fine leaves' to threads.
        let (coarse_listed, panes_listed, fine_listed) = (stats(&coarse[1]), stats(&panes[1]), stats(&fine[0]));
        assert!(coarse_listed.group_triangles > 0, "{coarse_listed:?}");
        assert!(panes_listed.tiled_triangles > 0, "{panes_listed:?}");
        assert_eq!(fine_listed.group_triangles + fine_listed.tiled_triangles, 0, "{fine_listed:?}");
        let (a, b) = (stats(&coarse[0]), stats(&fine[0]));
        assert!(a.fragments.abs_diff(b.fragments) <= a.fragments / 100, "{a:?} against {b:?}");
        let beyond = common::pixels_beyond(&coarse[0], &fine[0], 2);
        assert!(beyond <= (W * H / 100) as usize, "{}: {beyond} pixels differ by more than 2/255", technique.name());
        println!("{}: {beyond} pixels beyond 2/255; fragments {} and {}", technique.name(), a.fragments, b.fragments);
    }
}

/// The BLEND forest the benchmarks render (`ml_cpu::forest`), small: 4 trees of 512 leaf cards
/// (4,096 leaf triangles, each tree one object), framed by the loader's camera, 64 lights.
pub fn blend_forest() -> Scene {
    let (mut forest, _) = ml_cpu::gltf_scene::from_bytes(&ml_cpu::forest::forest_glb(4, 512, "BLEND"), None).expect("a good file");
    // 4×4×4 lights through the forest's box, each reaching a quarter of its diagonal.
    let (lo, hi) = forest.bounds();
    let radius = (hi - lo).length() / 4.0;
    forest.lights = (0..64u32)
        .map(|i| {
            let at = lo + (hi - lo) * (Vec3::new((i % 4) as f32, (i / 4 % 4) as f32, (i / 16) as f32) + 0.5) / 4.0;
            light(at.to_array(), radius, [0.6 + 0.1 * (i % 3) as f32, 0.7, 0.5 + 0.1 * (i % 5) as f32])
        })
        .collect();
    forest.cones.clear();
    forest.light_motion = 0.0;
    forest
}

/// The forest of `blend_forest` with its layers built three ways. Over tiles or a thread per
/// triangle: every byte and fragment the same, in the visibility technique (also at 8
/// samples) and the forward pass. The tiles' build tests every pixel of a tile, the other only
/// its triangle's box: the boxes hold every pixel whose centre (or, at 8 samples, some
/// sample) a leaf covers. The visibility raster draws the leaves' cores (their alpha is 0 or
/// 1 but at the texels' edges), so few fragments are left to its layers; without samples its
/// image is the forward pass's. And from the compute raster's candidates (the visibility
/// technique's own way without anti-aliasing): the soft samples the raster found, by its
/// coverage and alpha — a leaf's edge is cut where the raster cuts its core, not where the
/// unsnapped triangle puts it — so a few edge pixels differ from the other builds. With
/// samples the raster lists none: the per-triangle build's bytes.
#[test]
fn the_forest_is_the_same_from_either_build() {
    let forest = blend_forest();
    let with = |(technique, antialiasing), tiled_up_to, candidates| RenderSettings {
        shading: ShadingModel::Pbr,
        transparency: Some(TransparencySettings {
            tiled_up_to,
            candidate_list: if candidates { DEFAULT_CANDIDATE_LIST } else { 0 },
            ..TransparencySettings::default()
        }),
        antialiasing,
        ..settings(technique)
    };
    let runs =
        [(Technique::Forward, Antialiasing::Off), (Technique::Visibility, Antialiasing::Off), (Technique::Visibility, Antialiasing::X8)];
    let mut first = Vec::new();
    for run in runs {
        let out = common::render_each(&forest, &[with(run, 0, false), with(run, u32::MAX, false), with(run, 0, true)]);
        let (threads, tiles, listed) = (stats(&out[0]), stats(&out[1]), stats(&out[2]));
        let name = format!("{} at {} samples", run.0.name(), run.1.samples());
        println!("{name} forest: {} fragments, {} pixels differ", threads.fragments, common::pixels_beyond(&out[0], &out[1], 0));
        // The cores leave the layers a leaf's edges alone: still fragments to compare.
        let cores = run.0 == Technique::Visibility;
        assert!(threads.fragments > u64::from(W * H) / if cores { 400 } else { 4 }, "{name}: {threads:?}");
        assert_eq!(threads.fragments, tiles.fragments, "{name}");
        assert!(out[0].rgba == out[1].rgba, "{name}: the builds' images differ");
        if cores && run.1 == Antialiasing::Off {
            let cull = *out[2].stats.feature::<CullStats>().expect("culling stats");
            assert!(cull.layer_candidates > 0 && !cull.cores_per_triangle, "{name}: {cull:?}");
            let (beyond, far) = (common::pixels_beyond(&out[0], &out[2], 2), common::pixels_beyond(&out[0], &out[2], 32));
            println!(
                "{name}: from the candidates {} fragments ({} listed); {beyond} pixels beyond 2/255 of the per-triangle build's, {far} beyond 32/255",
                listed.fragments, cull.layer_candidates
            );
            assert!(listed.fragments > 0 && beyond <= (W * H / 400) as usize && far <= (W * H / 1000) as usize, "{name}: {beyond}, {far}");
        } else {
            assert!(out[2].rgba == out[0].rgba, "{name}: the compute raster listed candidates");
        }
        if run == (Technique::Visibility, Antialiasing::Off) {
            let forward = &first[0];
            for (build, out) in [("per-triangle", &out[0]), ("candidates", &out[2])] {
                let beyond = common::pixels_beyond(forward, out, 1);
                println!("{name}, {build}: {beyond} pixels beyond 1/255 of forward ({} fragments there)", stats(forward).fragments);
                assert!(stats(out).fragments < stats(forward).fragments / 4, "the cores left {:?}", stats(out));
                assert!(beyond <= (W * H / 100) as usize, "{name}, {build}: {beyond} pixels beyond 1/255 of forward");
            }
        }
        first.extend(out.into_iter().take(1));
    }
}

/// Inside a crown of the forest leaves cross the near plane, which the compute raster clips:
/// it cannot list their soft samples, and leaves the frame's cores to the per-triangle build
/// (the table says so) — every byte the image the per-triangle build gives without
/// candidates.
#[test]
fn a_frame_whose_raster_cannot_list_a_core_builds_the_cores_a_thread_per_triangle() {
    let mut forest = blend_forest();
    let crown = forest.objects.iter().find(|o| o.extras.has_core()).expect("a crown with cores");
    let (lo, hi) = crown.bounds();
    let eye = (lo + hi) * 0.5;
    forest.camera = Camera::looking_at(eye, eye + Vec3::new(1.0, -0.2, 0.3), 70.0, 0.05, 100.0);
    let with = |candidate_list| RenderSettings {
        shading: ShadingModel::Pbr,
        transparency: Some(TransparencySettings { candidate_list, ..TransparencySettings::default() }),
        ..settings(Technique::Visibility)
    };
    let out = common::render_each(&forest, &[with(DEFAULT_CANDIDATE_LIST), with(0)]);
    let cull = *out[0].stats.feature::<CullStats>().expect("culling stats");
    assert!(cull.cores_per_triangle, "{cull:?}");
    assert!(stats(&out[0]).fragments > 0);
    assert!(out[0].rgba == out[1].rgba);
    let row = out[0].stats.feature_rows().into_iter().find(|(name, _)| *name == "layer candidates").expect("a row of its own").1;
    assert!(row.contains("built a thread per triangle"), "{row}");
}

/// A candidates' list too short for the forest's soft samples: the frame's cores are left to
/// the per-triangle build (its bytes; the table says the list was full), the list grows, and
/// a later frame lists them all — the image a list long enough from the start gives.
#[test]
fn a_full_list_of_candidates_builds_the_cores_a_thread_per_triangle_and_grows() {
    let forest = blend_forest();
    let with = |candidate_list, frames| RenderSettings {
        shading: ShadingModel::Pbr,
        transparency: Some(TransparencySettings { candidate_list, ..TransparencySettings::default() }),
        frames,
        ..settings(Technique::Visibility)
    };
    let out = common::render_each(&forest, &[with(16, 1), with(0, 1), with(16, 4), with(DEFAULT_CANDIDATE_LIST, 1)]);
    let (full, grown) = (*out[0].stats.feature::<CullStats>().unwrap(), *out[2].stats.feature::<CullStats>().unwrap());
    assert!(full.cores_per_triangle && full.layer_candidates > 16 && full.candidate_room == 16, "{full:?}");
    let row = out[0].stats.feature_rows().into_iter().find(|(name, _)| *name == "layer candidates").expect("a row of its own").1;
    assert!(row.contains("the list was full"), "{row}");
    assert!(out[0].rgba == out[1].rgba, "the full list's frame is not the per-triangle build's");
    assert!(!grown.cores_per_triangle && grown.candidate_room >= grown.layer_candidates as u32, "{grown:?}");
    assert!(out[2].rgba == out[3].rgba, "the grown list's frame is not the long list's");
}

/// A mesh of one object whose two triangles meet at every point of a pixel (the same square
/// twice, one half red, one half blue through its texture, alpha one half): each pixel orders
/// the two by what they are, not by the order the build happened to list them in — the mesh
/// with its two squares swapped gives every byte the same, in every technique, where ties at
/// one depth of one object once went to the fragment listed first (a different colour for
/// each order: red over blue or blue over red).
#[test]
fn one_object_s_layers_at_one_depth_blend_the_same_in_either_order() {
    let twice = |red_first: bool| {
        let mut w = GltfWriter::new();
        let wall = w.material([0.6, 0.55, 0.5, 1.0], 0.0, 0.8);
        let wall_mesh = w.mesh(&[PrimitiveData { material: Some(wall), ..gltf_quad() }]);
        let upright = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2).to_array();
        w.node(json!({ "mesh": wall_mesh, "translation": [0.0, 0.0, -1.0], "rotation": upright, "scale": [4.0, 4.0, 4.0] }), true);
        // Texels: red, then blue; each square's corners sample one of them at its centre.
        let texture = w.texture(png(2, 1, &[230, 40, 30, 255, 30, 60, 230, 255]), "image/png");
        let square = gltf_quad();
        let mut positions = square.positions.clone();
        positions.extend_from_slice(&square.positions);
        let u = |texel: f32| vec![[texel, 0.5]; 4];
        let (first, second) = if red_first { (0.25, 0.75) } else { (0.75, 0.25) };
        let uvs = [u(first), u(second)].concat();
        let indices = vec![0, 2, 1, 1, 2, 3, 4, 6, 5, 5, 6, 7];
        let m = w.alpha_material(Some(texture), [1.0, 1.0, 1.0, 0.5], "BLEND", None, true);
        let both = PrimitiveData {
            normals: Some(vec![[0.0, 1.0, 0.0]; 8]),
            positions,
            uvs: Some(uvs),
            indices: Some((indices, ml_cpu::gltf_writer::IndexType::U16)),
            material: Some(m),
        };
        let mesh = w.mesh(&[both]);
        w.node(json!({ "mesh": mesh, "rotation": upright }), true);
        let (mut scene, _) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
        scene.camera = Camera::looking_at(Vec3::new(0.2, 0.1, 3.0), Vec3::ZERO, 50.0, 0.1, 20.0);
        scene.lights = vec![light([0.5, 0.8, 1.5], 5.0, [1.0, 0.95, 0.9]), light([-1.0, -0.5, 1.0], 4.0, [0.6, 0.7, 1.0])];
        scene.cones.clear();
        scene.light_motion = 0.0;
        scene
    };
    let all: Vec<RenderSettings> = Technique::ALL.iter().map(|&t| RenderSettings { shading: ShadingModel::Pbr, ..settings(t) }).collect();
    let (red_first, blue_first) = (common::render_each(&twice(true), &all), common::render_each(&twice(false), &all));
    for ((s, a), b) in all.iter().zip(&red_first).zip(&blue_first) {
        let name = s.technique.name();
        // Both squares left a fragment on every pixel they cover: two layers there.
        assert!(stats(a).fragments >= u64::from(W * H) / 4 && stats(a).fragments.is_multiple_of(2), "{name}: {:?}", stats(a));
        assert_eq!(stats(a).fragments, stats(b).fragments, "{name}");
        println!("{name}: {} fragments, {} pixels differ", stats(a).fragments, common::pixels_beyond(a, b, 0));
        assert!(a.rgba == b.rgba, "{name}: the order of the mesh's triangles changed the image");
    }
}
