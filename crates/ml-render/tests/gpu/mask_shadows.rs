//! Alpha-masked objects' shadows in the graphics shadow passes (depth_pass.rs MaskedPipeline):
//! a glTF quad with a square hole cut by its base colour texture's alpha (alphaMode MASK)
//! hangs above a floor. Its shadow, from the blinn-phong sun's map and from a point light's
//! cube in every graphics mode, must have the hole: every floor pixel whose way to the light
//! passes (with a margin) through the hole or beside the quad is lit exactly as with the quad
//! wholly cut out (base alpha 0), every one whose way crosses the solid plate is exactly as
//! dark as with the light off. The same quad with alphaMode OPAQUE shadows the hole's pixels
//! too (what the shadows looked like before masks reached them).

use crate::common;

use glam::Vec3;
use ml_cpu::blinn_phong::BlinnPhongLights;
use ml_cpu::camera::Camera;
use ml_cpu::gltf_writer::{png, quad, GltfWriter, PrimitiveData};
use ml_cpu::gpu_types::{GpuLayout, PointLight};
use ml_cpu::scene::Scene;
use ml_render::internals::ShadowMaskPush;
use ml_render::settings::multiview_depth_is_broken;
use ml_render::{OmniShadowMode, OmniShadowSettings, RenderOutput, RenderSettings, ShadingModel, SunShadowMode, Technique};
use ml_vk::{Context, ContextDesc};
use serde_json::json;

const SIZE: u32 = 96;
/// The plate's height above the floor (the plate is glTF's quad: [−1, 1]² about its centre).
const PLATE_Y: f32 = 1.5;
/// Side of the plate's texture in texels; the hole is its middle half: texels 4..12, which
/// bilinear filtering cuts at alpha ½ exactly on the texel edges, u and v in [¼, ¾] — the
/// plate's points with |x|, |z| < ½.
const TEXELS: u32 = 16;
const HOLE: f32 = 0.5;
/// How far (in the plate's units) a floor point's way to the light must pass from the hole's
/// edge or the plate's to be checked: a few shadow-map or cube texels, with PCF, are far less.
const MARGIN: f32 = 0.1;
const POINT_LIGHT: Vec3 = Vec3::new(0.0, 3.0, 0.0);

/// How the plate is made in a variant of the scene.
#[derive(Clone, Copy, PartialEq)]
enum Plate {
    /// alphaMode MASK, base alpha 1: cut where the texture's alpha is 0.
    Masked,
    /// alphaMode MASK, base alpha 0: cut everywhere (no shadow at all).
    Gone,
    /// alphaMode OPAQUE: the texture's alpha is ignored.
    Opaque,
}

/// A floor ([−4, 4]² at y = 0) and the plate above it, written as glTF and loaded; seen from
/// above and in front.
fn scene(plate: Plate) -> Scene {
    let mut w = GltfWriter::new();
    let floor = w.material([0.8, 0.8, 0.8, 1.0], 0.0, 0.9);
    let floor_mesh = w.mesh(&[PrimitiveData { material: Some(floor), ..quad() }]);
    w.node(json!({ "mesh": floor_mesh, "scale": [4.0, 1.0, 4.0] }), true);
    let texels: Vec<u8> = (0..TEXELS * TEXELS)
        .flat_map(|i| {
            let (x, y) = (i % TEXELS, i / TEXELS);
            let hole = (4..12).contains(&x) && (4..12).contains(&y);
            [200, 180, 160, if hole { 0 } else { 255 }]
        })
        .collect();
    let texture = w.texture(png(TEXELS, TEXELS, &texels), "image/png");
    let m = w.textured_material(Some(texture), None);
    let material = &mut w.json["materials"][m];
    material["alphaMode"] = json!(if plate == Plate::Opaque { "OPAQUE" } else { "MASK" });
    if plate == Plate::Gone {
        material["pbrMetallicRoughness"]["baseColorFactor"] = json!([1.0, 1.0, 1.0, 0.0]);
    }
    let plate_mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(json!({ "mesh": plate_mesh, "translation": [0.0, PLATE_Y, 0.0] }), true);
    let (mut scene, warnings) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(scene.objects.len(), 2);
    assert_eq!(scene.objects[1].extras.alpha_mode.cutoff().is_some(), plate != Plate::Opaque);
    scene.camera = Camera::looking_at(Vec3::new(0.5, 5.0, 5.0), Vec3::new(0.4, 0.0, 0.2), 50.0, 0.1, 50.0);
    scene
}

/// Where a floor point's way to the light crosses the plate's plane, relative to the plate's
/// centre (x, z), and what the light sees there: Some(true) lit (the hole, or beside the plate),
/// Some(false) the solid plate, None within MARGIN of an edge.
fn seen_through(q: (f32, f32)) -> Option<bool> {
    let r = q.0.abs().max(q.1.abs());
    if !(HOLE - MARGIN..=1.0 + MARGIN).contains(&r) {
        Some(true)
    } else if r > HOLE + MARGIN && r < 1.0 - MARGIN {
        Some(false)
    } else {
        None
    }
}

/// A pixel that sees the floor: whether the light reaches it, and where its way to the light
/// crosses the plate's plane (x, z about the plate's centre).
#[derive(Clone, Copy)]
struct FloorPixel {
    at: (u32, u32),
    lit: bool,
    plate: (f32, f32),
}

/// Every pixel that sees the floor (well inside it, the plate not in the way — a pixel seen
/// through the hole is left out too) with what the light sees from there (`towards_plate`: a
/// floor point → where its way to the light meets the plate's plane).
fn floor_pixels(camera: &Camera, towards_plate: impl Fn(Vec3) -> Vec3) -> Vec<FloorPixel> {
    let mut pixels = Vec::new();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let (o, d) = camera.pixel_ray(x, y, SIZE, SIZE);
            if d.y >= -1e-3 {
                continue;
            }
            let p = o + d * (-o.y / d.y);
            let at_plate = o + d * ((PLATE_Y - o.y) / d.y);
            if p.x.abs() > 3.8 || p.z.abs() > 3.8 || at_plate.x.abs().max(at_plate.z.abs()) < 1.0 + MARGIN {
                continue;
            }
            let q = towards_plate(p);
            if let Some(lit) = seen_through((q.x, q.z)) {
                pixels.push(FloorPixel { at: (x, y), lit, plate: (q.x, q.z) });
            }
        }
    }
    pixels
}

/// Count of lit and shadowed pixels checked; panics (with the first few) where `shadowed`
/// differs by more than 1/255 from `lit_reference` at a lit pixel or from `dark_reference` at a
/// shadowed one.
fn check_shape(
    what: &str,
    pixels: &[FloorPixel],
    shadowed: &RenderOutput,
    (lit_reference, dark_reference): (&RenderOutput, &RenderOutput),
) -> (usize, usize) {
    let mut wrong = Vec::new();
    let (mut lit, mut dark) = (0, 0);
    for p in pixels {
        let ((x, y), is_lit) = (p.at, p.lit);
        let reference = if is_lit { lit_reference } else { dark_reference };
        let (got, want) = (common::pixel(shadowed, x, y), common::pixel(reference, x, y));
        if got.iter().zip(want).any(|(a, b)| a.abs_diff(b) > 1) {
            wrong.push(((x, y), p.plate, is_lit, got, want));
        }
        if is_lit {
            lit += 1;
        } else {
            dark += 1;
        }
    }
    println!("{what}: {lit} lit and {dark} shadowed floor pixels checked, {} wrong", wrong.len());
    assert!(wrong.is_empty(), "{what}: (pixel, plate point, lit, rendered, expected): {:?}", &wrong[..wrong.len().min(10)]);
    (lit, dark)
}

/// The pixels of `pixels` whose plate point is in the hole (with the margin).
fn in_hole(pixels: &[FloorPixel]) -> Vec<FloorPixel> {
    pixels.iter().filter(|p| p.plate.0.abs().max(p.plate.1.abs()) < HOLE - MARGIN).copied().collect()
}

/// The pixel of `pixels` lit (or not) as `lit` says whose plate point is nearest to `q` (for
/// the printed sample values).
fn nearest(pixels: &[FloorPixel], lit: bool, q: (f32, f32)) -> (u32, u32) {
    let distance = |p: &FloorPixel| (p.plate.0 - q.0).hypot(p.plate.1 - q.1);
    pixels.iter().filter(|p| p.lit == lit).min_by(|a, b| distance(a).total_cmp(&distance(b))).expect("pixels of both kinds").at
}

fn sun() -> Vec3 {
    Vec3::new(0.5, -1.0, 0.3).normalize()
}

fn sun_scene(plate: Plate, sun_on: bool) -> Scene {
    let mut s = scene(plate);
    let mut lights =
        BlinnPhongLights { sun_direction: sun(), sun_strength: Vec3::splat(if sun_on { 1.0 } else { 0.0 }), ..Default::default() };
    lights.spot.strength = Vec3::ZERO;
    lights.ambient = Vec3::splat(0.1);
    s.blinn_phong = lights;
    // A light buffer may not be empty: one far away.
    s.lights = vec![PointLight { position_radius: [100.0, 100.0, 100.0, 0.1], color: [1.0; 4] }];
    s
}

/// The blinn-phong sun's shadow map (the graphics pass, the default) cuts the plate's hole:
/// the floor under the hole, along the sun, is lit; under the plate it is in shadow.
#[test]
fn the_suns_shadow_has_the_masks_hole() {
    let mut settings = RenderSettings::new(Technique::Forward, SIZE, SIZE);
    settings.shading = ShadingModel::BlinnPhong;
    settings.sun_shadow = SunShadowMode::Graphics;
    let variants = [(Plate::Masked, true), (Plate::Gone, true), (Plate::Masked, false), (Plate::Opaque, true)];
    let scenes: Vec<Scene> = variants.iter().map(|&(plate, on)| sun_scene(plate, on)).collect();
    let outputs: Vec<RenderOutput> = scenes.iter().map(|s| common::render(s.clone(), settings)).collect();
    let [masked, gone, sun_off, opaque] = [&outputs[0], &outputs[1], &outputs[2], &outputs[3]];
    // Towards the sun from floor point p to the plate's plane.
    let towards_plate = |p: Vec3| p - sun() * ((PLATE_Y - p.y) / -sun().y);
    let pixels = floor_pixels(&scenes[0].camera, towards_plate);
    let (hole_px, solid_px) = (nearest(&pixels, true, (0.0, 0.0)), nearest(&pixels, false, (0.0, 0.75)));
    println!(
        "sun: floor under the hole's centre {hole_px:?}: masked {:?}, cut out {:?}, sun off {:?}, opaque {:?}; under the plate {solid_px:?}: masked {:?}, sun off {:?}",
        common::pixel(masked, hole_px.0, hole_px.1),
        common::pixel(gone, hole_px.0, hole_px.1),
        common::pixel(sun_off, hole_px.0, hole_px.1),
        common::pixel(opaque, hole_px.0, hole_px.1),
        common::pixel(masked, solid_px.0, solid_px.1),
        common::pixel(sun_off, solid_px.0, solid_px.1),
    );
    let (lit, dark) = check_shape("sun, masked plate", &pixels, masked, (gone, sun_off));
    let hole = in_hole(&pixels);
    assert!(lit >= 1500 && dark >= 300 && hole.len() >= 100, "too few pixels checked ({} in the hole)", hole.len());
    // The sun must make a difference there, and the opaque plate shadows the hole's pixels.
    let [l, d] = [gone, sun_off].map(|o| common::pixel(o, hole_px.0, hole_px.1)[1]);
    assert!(l >= d + 40, "the sun adds too little light to compare: {l} vs {d}");
    let hole_dark: Vec<_> = hole.iter().map(|&p| FloorPixel { lit: false, ..p }).collect();
    check_shape("sun, opaque plate (the hole's pixels)", &hole_dark, opaque, (gone, sun_off));
}

/// The graphics point-light shadow modes this device renders (multiview where it works).
fn graphics_modes() -> Vec<OmniShadowMode> {
    let ctx = Context::new(&ContextDesc::default()).expect("a Vulkan device");
    let mut modes = vec![OmniShadowMode::Copy, OmniShadowMode::Direct];
    if ctx.info.features.shader_output_layer {
        modes.push(OmniShadowMode::Layered);
    }
    if ctx.info.features.multiview && !multiview_depth_is_broken(&ctx) {
        modes.push(OmniShadowMode::Multiview);
    }
    modes
}

fn point_scene(plate: Plate, light_on: bool) -> Scene {
    let mut s = scene(plate);
    let c = if light_on { 4.0 } else { 0.0 };
    s.lights = vec![PointLight { position_radius: [POINT_LIGHT.x, POINT_LIGHT.y, POINT_LIGHT.z, 9.0], color: [c, c, c, 0.0] }];
    s.ambient = 0.05;
    s
}

fn point_settings(omni: Option<OmniShadowMode>) -> RenderSettings {
    let mut s = RenderSettings::new(Technique::Forward, SIZE, SIZE);
    s.shading = ShadingModel::Pbr;
    s.omni = omni.map(|mode| OmniShadowSettings { mode, lights: 1, all: false, size: 256 });
    s
}

/// A point light above the plate: its cube, drawn by each graphics mode (copy, direct,
/// layered, multiview where the driver renders it right), cuts the hole — the floor under the
/// hole is lit, under the plate it is in shadow.
#[test]
fn point_light_shadows_have_the_masks_hole_in_every_graphics_mode() {
    let modes = graphics_modes();
    // Shadowed renders of the masked plate in each mode, and of the opaque one (direct); the
    // references without shadows: the plate cut out wholly, and the light off.
    let masked = point_scene(Plate::Masked, true);
    let shadowed = common::render_each(&masked, &modes.iter().map(|&m| point_settings(Some(m))).collect::<Vec<_>>());
    let opaque = common::render(point_scene(Plate::Opaque, true), point_settings(Some(OmniShadowMode::Direct)));
    let gone = common::render(point_scene(Plate::Gone, true), point_settings(None));
    let light_off = common::render(point_scene(Plate::Masked, false), point_settings(None));
    // From floor point p towards the light, to the plate's plane.
    let towards_plate = |p: Vec3| POINT_LIGHT + (p - POINT_LIGHT) * ((POINT_LIGHT.y - PLATE_Y) / (POINT_LIGHT.y - p.y));
    let pixels = floor_pixels(&masked.camera, towards_plate);
    let (hole_px, solid_px) = (nearest(&pixels, true, (0.0, 0.0)), nearest(&pixels, false, (0.0, 0.75)));
    for (mode, out) in modes.iter().zip(&shadowed) {
        println!(
            "{mode:?}: floor under the hole's centre {hole_px:?} {:?} (cut out {:?}, light off {:?}, opaque plate {:?}); under the plate {solid_px:?} {:?} (light off {:?})",
            common::pixel(out, hole_px.0, hole_px.1),
            common::pixel(&gone, hole_px.0, hole_px.1),
            common::pixel(&light_off, hole_px.0, hole_px.1),
            common::pixel(&opaque, hole_px.0, hole_px.1),
            common::pixel(out, solid_px.0, solid_px.1),
            common::pixel(&light_off, solid_px.0, solid_px.1),
        );
        let (lit, dark) = check_shape(&format!("{mode:?}, masked plate"), &pixels, out, (&gone, &light_off));
        assert!(lit >= 1500 && dark >= 300, "{mode:?}: too few pixels checked");
    }
    let hole = in_hole(&pixels);
    assert!(hole.len() >= 100, "only {} pixels under the hole", hole.len());
    let [l, d] = [&gone, &light_off].map(|o| common::pixel(o, hole_px.0, hole_px.1)[1]);
    assert!(l >= d + 40, "the light adds too little to compare: {l} vs {d}");
    let hole_dark: Vec<_> = hole.iter().map(|&p| FloorPixel { lit: false, ..p }).collect();
    check_shape("Direct, opaque plate (the hole's pixels)", &hole_dark, &opaque, (&gone, &light_off));
}

/// ShadowMaskPush (Rust) has the member offsets and size the masked shaders' push block has.
#[test]
fn the_masked_push_constants_match_the_shaders() {
    use spirq::ty::Type;
    for shader in [ml_shaders::SHADOW_MASKED_VERT, ml_shaders::OMNI_SHADOW_MASKED_FRAG, ml_shaders::OMNI_SHADOW_LAYERED_MASKED_VERT] {
        let words: Vec<u32> = shader.spirv.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        let entries = spirq::ReflectConfig::new().spv(words).ref_all_rscs(true).reflect().expect("reflection");
        let mut found = None;
        for entry in entries {
            for var in &entry.vars {
                let Type::Struct(block) = var.ty() else { continue };
                for m in &block.members {
                    if let Type::Struct(s) = &m.ty {
                        if s.name() == Some(ShadowMaskPush::GLSL_NAME) {
                            let offsets: Vec<(String, usize)> =
                                s.members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset.unwrap())).collect();
                            let last = s.members.last().unwrap();
                            found = Some((offsets, last.offset.unwrap() + last.ty.nbyte().unwrap()));
                        }
                    }
                }
            }
        }
        let (offsets, size) = found.unwrap_or_else(|| panic!("{} has no ShadowMaskPush", shader.file));
        let rust: Vec<(String, usize)> = ShadowMaskPush::field_offsets().into_iter().map(|(n, o)| (n.to_owned(), o)).collect();
        assert_eq!(offsets, rust, "{}", shader.file);
        assert_eq!(size, size_of::<ShadowMaskPush>(), "{}", shader.file);
    }
}
