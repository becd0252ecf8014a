//! Anti-aliasing (docs/DESIGN.md#anti-aliasing), several coverage samples a pixel — the
//! visibility technique's compute raster, the mesh techniques' multisampled attachments:
//! - against the same view supersampled 8×8 and filtered in linear light
//!   (`ml_cpu::supersample`), 8 samples of the compute raster cut the RMS error of the image
//!   without anti-aliasing to at most a third, on the bench scene and on foliage of
//!   alpha-masked leaves; 4 samples (lavapipe's most) of the forward pass, the deferred
//!   subpasses, deferred-compute and the hybrid and hardware rasters to at most half;
//! - it changes nothing it must not: culling off, and the light grid's marks on or off, give
//!   the same image byte for byte; two renders are byte-identical;
//! - a pixel shades each surface its samples hold once: a view filled by one quad shades a
//!   surface per pixel, and two where its diagonal splits the samples;
//! - transparent layers: small glass panes turned every way, over opaque edges and under
//!   others, with 8 samples of the compute raster (4 of the hybrid and hardware rasters) cut
//!   the error to at most a third (a half); two renders are byte-identical, and the pixels
//!   without layers are those of the same view without the glass;
//! - specular anti-aliasing: metal under a grainy normal map, one sample a pixel, with its
//!   highlights widened by the normals' spread comes at most 0.6 of the error without (the
//!   reference lights the unwidened map 64 times a pixel), the forward pass and the G-buffer's
//!   lighting within 2/255 of the visibility technique.
//!
//! Validation (with synchronization validation) stays silent.

use crate::common;
use crate::common::view;

use glam::{Quat, Vec3};
use ml_cpu::camera::Camera;
use ml_cpu::gltf_writer::{cutout, png, quad, GltfWriter, PrimitiveData, CUTOUT_SIZE};
use ml_cpu::gpu_types::PointLight;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{AlphaMode, Object, Scene};
use ml_cpu::supersample::{downsample, rms_difference};
use ml_render::{Antialiasing, AntialiasingStats, Raster, RenderOutput, RenderSettings, ShadingModel, Technique, TransparencySettings};
use rand::{Rng, SeedableRng};
use serde_json::json;

/// The reference's supersampling, each axis.
const REFERENCE: u32 = 8;

/// The visibility technique with the compute raster at `width`×`height`, samples `aa`.
fn visibility(width: u32, height: u32, aa: Antialiasing) -> RenderSettings {
    RenderSettings {
        raster: Raster::compute(Raster::DEFAULT_SPLIT),
        antialiasing: aa,
        ..RenderSettings::new(Technique::Visibility, width, height)
    }
}

/// RMS errors (8-bit units) against the supersampled reference of `base`'s view: of `base`
/// (anti-aliasing off), then of each of `variants`, named (technique and samples) in `what`'s
/// line; and the variants' renders.
fn errors(what: &str, scene: &Scene, base: RenderSettings, variants: &[RenderSettings]) -> (f64, Vec<f64>, Vec<RenderOutput>) {
    let (w, h) = (base.width, base.height);
    let big = RenderSettings { width: w * REFERENCE, height: h * REFERENCE, ..base };
    let settings: Vec<RenderSettings> = [big, base].into_iter().chain(variants.iter().copied()).collect();
    let mut outputs = common::render_each(scene, &settings);
    let reference = downsample(&outputs[0].rgba, (w * REFERENCE, h * REFERENCE), REFERENCE);
    let e_off = rms_difference(&outputs[1].rgba, &reference);
    let errors: Vec<f64> = outputs[2..].iter().map(|o| rms_difference(&o.rgba, &reference)).collect();
    for (v, e) in variants.iter().zip(&errors) {
        let (technique, samples) = (v.technique.name(), v.antialiasing.samples());
        let raster = if v.technique == Technique::Visibility { format!(" ({} raster)", v.raster.name()) } else { String::new() };
        println!("{what} {w}x{h}: RMS error against the {REFERENCE}x{REFERENCE} reference {e_off:.3} without anti-aliasing, {e:.3} by {technique}{raster} with {samples} samples ({:.2} of it)", e / e_off);
    }
    (e_off, errors, outputs.split_off(2))
}

/// The mesh techniques at `aa` (lavapipe's rasterizer offers 4 samples a pixel, not 8).
fn meshes(technique: Technique, base: RenderSettings, aa: Antialiasing) -> RenderSettings {
    RenderSettings { antialiasing: aa, raster: Raster::Hardware, ..RenderSettings { technique, ..base } }
}

/// Foliage: 300 alpha-masked, double-sided leaves (the cut-out plate, small, turned every way)
/// in a bush over a floor, 128 lights.
fn foliage() -> Scene {
    let mut w = GltfWriter::new();
    let texture = w.texture(png(CUTOUT_SIZE, CUTOUT_SIZE, &cutout([255, 255, 255])), "image/png");
    let leaf = w.alpha_material(Some(texture), [0.25, 0.7, 0.2, 1.0], "MASK", None, true);
    let floor = w.material([0.5, 0.45, 0.4, 1.0], 0.0, 0.8);
    let floor_mesh = w.mesh(&[PrimitiveData { material: Some(floor), ..quad() }]);
    w.node(json!({ "mesh": floor_mesh, "scale": [6.0, 6.0, 6.0] }), true);
    let leaf_mesh = w.mesh(&[PrimitiveData { material: Some(leaf), ..quad() }]);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(52);
    for _ in 0..300 {
        let at = Vec3::new(rng.random_range(-1.5..1.5), rng.random_range(0.3..2.8), rng.random_range(-1.5..1.5));
        let turn =
            Quat::from_euler(glam::EulerRot::XYZ, rng.random_range(0.0..6.3), rng.random_range(0.0..6.3), rng.random_range(0.0..6.3));
        let scale = rng.random_range(0.12..0.3);
        w.node(
            json!({ "mesh": leaf_mesh, "translation": at.to_array(), "rotation": turn.to_array(), "scale": [scale, scale, scale] }),
            true,
        );
    }
    let (mut scene, _) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    scene.camera = Camera::looking_at(Vec3::new(0.5, 2.2, 5.5), Vec3::new(0.0, 1.5, 0.0), 45.0, 0.1, 50.0);
    lit(scene, &mut rng, 128, (Vec3::new(-3.0, 0.2, -3.0), Vec3::new(3.0, 3.5, 3.0)), 0.3..1.0, 1.0..3.0)
}

/// `scene` under `count` still point lights (none of its own, no spots) at random in the box
/// `(lo, hi)`, their colours' channels and radii at random in `colour` and `radius`.
fn lit(
    mut scene: Scene,
    rng: &mut rand_chacha::ChaCha8Rng,
    count: usize,
    (lo, hi): (Vec3, Vec3),
    colour: std::ops::Range<f32>,
    radius: std::ops::Range<f32>,
) -> Scene {
    scene.lights = (0..count)
        .map(|_| {
            let p = Vec3::new(rng.random_range(lo.x..hi.x), rng.random_range(lo.y..hi.y), rng.random_range(lo.z..hi.z));
            let c = [0; 3].map(|_| rng.random_range(colour.clone()));
            PointLight { position_radius: [p.x, p.y, p.z, rng.random_range(radius.clone())], color: [c[0], c[1], c[2], 0.0] }
        })
        .collect();
    scene.cones.clear();
    scene.light_motion = 0.0;
    scene
}

/// Four samples a pixel: what lavapipe's rasterizer offers the mesh techniques and the hardware
/// and hybrid visibility rasters; measured, they leave 0.40 of the bench scene's error (the
/// compute raster 0.40 at 4 samples, 0.30 at 8).
const FOUR_SAMPLES_AT_MOST: f64 = 0.5;

#[test]
fn samples_cut_the_error_against_the_supersampled_reference() {
    let bench = ml_cpu::bench_scene::bench_scene(1024, 1, 20).expect("the bench scene");
    let base = visibility(320, 180, Antialiasing::Off);
    // The hybrid raster's hardware half draws without attachments, the hardware raster into
    // multisampled ones, at what lavapipe offers there: 4 samples.
    let hybrid = RenderSettings { antialiasing: Antialiasing::X4, raster: Raster::hybrid(Raster::DEFAULT_SPLIT), ..base };
    let hardware = RenderSettings { antialiasing: Antialiasing::X4, raster: Raster::Hardware, ..base };
    // The forward pass and the deferred subpasses with their light lists (the brute-force
    // loops' images are theirs, techniques.rs; over 1,024 lights they cost CI's time).
    let variants = [
        RenderSettings { antialiasing: Antialiasing::X8, ..base },
        meshes(Technique::ClusteredGpu, base, Antialiasing::X4),
        meshes(Technique::DeferredClustered, base, Antialiasing::X4),
        meshes(Technique::DeferredCompute, base, Antialiasing::X4),
        hybrid,
        hardware,
    ];
    let (off, aa, _) = errors("bench scene", &bench, base, &variants);
    assert!(aa[0] * 3.0 <= off, "bench scene: {:.3} with 8 samples against {off:.3} without", aa[0]);
    for (v, e) in variants[1..].iter().zip(&aa[1..]) {
        assert!(
            *e <= FOUR_SAMPLES_AT_MOST * off,
            "bench scene: {:.3} by {} ({} raster) with 4 samples against {off:.3} without",
            e,
            v.technique.name(),
            v.raster.name()
        );
    }
    let leaves = foliage();
    let base = RenderSettings { shading: ShadingModel::Pbr, ..visibility(160, 120, Antialiasing::Off) };
    let variants = [
        RenderSettings { antialiasing: Antialiasing::X8, ..base },
        meshes(Technique::Forward, base, Antialiasing::X4),
        RenderSettings { antialiasing: Antialiasing::X4, raster: Raster::Hardware, ..base },
    ];
    let (off, aa, _) = errors("foliage", &leaves, base, &variants);
    assert!(aa[0] * 3.0 <= off, "foliage: {:.3} with 8 samples against {off:.3} without", aa[0]);
    for (v, e) in variants[1..].iter().zip(&aa[1..]) {
        let what = format!("{} ({} raster)", v.technique.name(), v.raster.name());
        assert!(*e <= FOUR_SAMPLES_AT_MOST * off, "foliage: {e:.3} by {what} with 4 samples against {off:.3} without");
    }
}

/// `errors` of `scene`, its transparent objects blended in layers (pbr), at `size` without
/// samples and with 8: (without, with). One node a pixel, so that the 8×8 reference's pool
/// fits a storage buffer lavapipe binds.
fn layered_errors(what: &str, scene: &Scene, (width, height): (u32, u32)) -> (f64, f64) {
    let layers = Some(TransparencySettings { budget: 1, ..TransparencySettings::default() });
    let base = RenderSettings { shading: ShadingModel::Pbr, transparency: layers, ..visibility(width, height, Antialiasing::Off) };
    let (off, aa, _) = errors(what, scene, base, &[RenderSettings { antialiasing: Antialiasing::X8, ..base }]);
    (off, aa[0])
}

/// Soft-edged foliage (the BLEND forest, its leaves' alpha 0 or 1 but at the texels' edges):
/// the raster draws each sample where the alpha is 1 as opaque (the leaves' cores) and the
/// layers only the rest, as a supersampled render, where each sample has its own alpha, does.
/// Measured on lavapipe, 8 samples leave 0.34 of the error without them; taking the layers'
/// alpha once a pixel for all its samples left 0.59.
#[test]
fn blended_foliage_s_samples_take_their_own_alpha() {
    let (off, aa) = layered_errors("BLEND forest", &crate::transparency::blend_forest(), (160, 120));
    assert!(aa <= 0.45 * off, "BLEND forest: {aa:.3} with 8 samples against {off:.3} without");
}

/// A soft-edged BLEND decal (a ring of alpha 1 fading to 0 both ways) 2 mm in front of a lit
/// wall 3 m away, seen head-on: its samples of alpha 1 are drawn as opaque (cores) and the
/// others blended, and its soft edges, whose layers lie 2 mm in front of the wall, stay
/// layers at 8 samples as without them. The view holds no geometric edge, so samples add
/// nothing here: their error stays near the one without them (measured 0.189 against 0.179;
/// taken as lying on the wall by a slack of a thousandth of the distance, the soft edges were
/// lost: 11.45).
#[test]
fn a_soft_decal_just_in_front_of_a_wall_keeps_its_soft_edges() {
    let mut w = GltfWriter::new();
    let wall = w.material([0.6, 0.55, 0.5, 1.0], 0.0, 0.8);
    let texture = w.texture(crate::transparency::leaf_png(), "image/png");
    let decal = w.alpha_material(Some(texture), [0.9, 0.2, 0.1, 1.0], "BLEND", None, false);
    let upright = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2).to_array();
    for (material, z, scale) in [(wall, 0.0, 2.0), (decal, 0.002, 0.8)] {
        let mesh = w.mesh(&[PrimitiveData { material: Some(material), ..quad() }]);
        w.node(json!({ "mesh": mesh, "translation": [0.0, 0.0, z], "rotation": upright, "scale": [scale, scale, scale] }), true);
    }
    let (mut scene, _) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    scene.camera = Camera::looking_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 45.0, 0.1, 20.0);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let scene = lit(scene, &mut rng, 8, (Vec3::new(-1.5, -1.5, 0.5), Vec3::new(1.5, 1.5, 2.0)), 0.5..1.0, 2.5..4.0);
    let (off, aa) = layered_errors("decal", &scene, (128, 96));
    assert!(aa <= 2.0 * off, "decal: {aa:.3} with 8 samples against {off:.3} without");
}

#[test]
fn samples_change_no_pixel_they_must_not() {
    // The marks' pass runs where the settings leave it on (their default).
    let scene = ml_cpu::bench_scene::bench_scene(4096, 3, 12).expect("the bench scene");
    let base = visibility(160, 96, Antialiasing::X8);
    assert!(base.light_grid_marks);
    let settings = [base, base, RenderSettings { culling: false, ..base }, RenderSettings { light_grid_marks: false, ..base }];
    let outputs = common::render_each(&scene, &settings);
    for (what, out) in ["a second render", "culling off", "the light grid's marks off"].iter().zip(&outputs[1..]) {
        let (worst, pixels) = common::max_difference(&outputs[0], out);
        assert_eq!((worst, pixels), (0, 0), "{what}: {pixels} pixels differ, by up to {worst}/255");
    }
    let leaves = foliage();
    let base = visibility(128, 96, Antialiasing::X8);
    let outputs = common::render_each(&leaves, &[base, RenderSettings { culling: false, ..base }]);
    assert_eq!(common::max_difference(&outputs[0], &outputs[1]), (0, 0), "foliage: culling off changed the image");
}

#[test]
fn a_pixel_shades_each_surface_its_samples_hold_once() {
    // One quad filling the view: two triangles, their shared diagonal across the image.
    let mut w = GltfWriter::new();
    let m = w.material([0.7, 0.7, 0.7, 1.0], 0.0, 0.5);
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(
        json!({ "mesh": mesh, "rotation": Quat::from_rotation_x(std::f32::consts::FRAC_PI_2).to_array(), "scale": [8.0, 8.0, 8.0] }),
        true,
    );
    let (mut scene, _) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    scene.camera = Camera::looking_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 60.0, 0.1, 20.0);
    scene.lights = vec![PointLight { position_radius: [0.0, 0.0, 2.0, 10.0], color: [1.0, 1.0, 1.0, 0.0] }];
    let (width, height) = (64, 48);
    for aa in [Antialiasing::X4, Antialiasing::X8, Antialiasing::X16] {
        let out = common::render(scene.clone(), visibility(width, height, aa));
        let stats = out.stats.feature::<AntialiasingStats>().expect("anti-aliasing reports its samples");
        let pixels = u64::from(width * height);
        // The diagonal crosses at most width + height pixels, each shading both triangles.
        let diagonal = u64::from(width + height);
        let surfaces = stats.surfaces.expect("the visibility lighting counts them");
        println!("{} samples: {surfaces} surfaces shaded over {pixels} pixels", aa.samples());
        assert!(surfaces > pixels && surfaces <= pixels + diagonal, "{} samples: {surfaces} surfaces", aa.samples());
    }
}

/// A quad facing the camera (+Z), `half` to each side, turned `turn` radians about the view
/// axis; glass (BLEND) where `alpha` is given.
fn turned_quad(at: Vec3, half: f32, turn: f32, albedo: [f32; 3], alpha: Option<f32>) -> Object {
    let rotation = Quat::from_rotation_z(turn) * Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let material = Material { albedo: Vec3::from(albedo), roughness: 0.5, metallic: 0.0 };
    let mut o = Object::placed(MeshKind::Plane, Vec3::ZERO, 1.0, material);
    o.transform = glam::Mat4::from_scale_rotation_translation(Vec3::splat(half), rotation, at);
    if let Some(a) = alpha {
        o.extras.alpha_mode = AlphaMode::Blend;
        o.extras.base_alpha = a;
    }
    o
}

/// A lit wall; dark opaque quads before it, glass panes (BLEND) in front of them, bright
/// opaque quads in front of the glass — small, turned every way about the view axis: edges of
/// glass over opaque edges, and of opaque surfaces over glass. `with_glass` false leaves the
/// panes out (the rest as placed with them).
fn glass_over_edges(with_glass: bool) -> Scene {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(57);
    let mut objects = vec![turned_quad(Vec3::ZERO, 6.0, 0.0, [0.8, 0.75, 0.7], None)];
    let mut place = |z: f32, half: std::ops::Range<f32>| {
        let at = Vec3::new(rng.random_range(-1.6..1.6), rng.random_range(-1.2..1.2), z);
        (at, rng.random_range(half), rng.random_range(0.0..3.2f32), [0; 3].map(|_| rng.random_range(0.1..1.0f32)))
    };
    for i in 0..12 {
        let (at, half, turn, c) = place(0.3 + 0.02 * i as f32, 0.15..0.45);
        objects.push(turned_quad(at, half, turn, [0.2 * c[0], 0.2 * c[1], 0.3 * c[2]], None));
    }
    for i in 0..16 {
        let (at, half, turn, c) = place(0.8 + 0.03 * i as f32, 0.2..0.5);
        let alpha = 0.3 + 0.4 * c[0];
        if with_glass {
            objects.push(turned_quad(at, half, turn, c, Some(alpha)));
        }
    }
    for i in 0..6 {
        let (at, half, turn, _) = place(1.5 + 0.02 * i as f32, 0.08..0.25);
        objects.push(turned_quad(at, half, turn, [0.95, 0.92, 0.85], None));
    }
    let lights = vec![
        PointLight { position_radius: [1.2, 1.0, 2.5, 6.0], color: [1.0, 0.9, 0.8, 0.0] },
        PointLight { position_radius: [-1.5, -0.5, 2.0, 5.0], color: [0.6, 0.7, 1.0, 0.0] },
        PointLight { position_radius: [0.3, 0.2, 1.3, 1.5], color: [1.5, 1.0, 0.6, 0.0] },
    ];
    let camera = Camera::looking_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 50.0, 0.1, 20.0);
    let mut scene = Scene::new(objects, lights, camera);
    scene.light_motion = 0.0;
    scene
}

#[test]
fn transparent_layers_are_anti_aliased_over_and_under_opaque_edges() {
    let scene = glass_over_edges(true);
    // Two nodes a pixel on average: room for the two panes everywhere, and a pool that one
    // storage buffer holds at the reference's size on lavapipe.
    let layers = Some(TransparencySettings { budget: 2, ..TransparencySettings::default() });
    let base = RenderSettings { transparency: layers, ..visibility(160, 120, Antialiasing::Off) };
    let variants = [
        RenderSettings { antialiasing: Antialiasing::X8, ..base },
        RenderSettings { antialiasing: Antialiasing::X4, raster: Raster::hybrid(Raster::DEFAULT_SPLIT), ..base },
        RenderSettings { antialiasing: Antialiasing::X4, raster: Raster::Hardware, ..base },
    ];
    let (off, aa, _) = errors("glass over edges", &scene, base, &variants);
    assert!(aa[0] * 3.0 <= off, "glass over edges: {:.3} with 8 samples against {off:.3} without", aa[0]);
    for (v, e) in variants[1..].iter().zip(&aa[1..]) {
        assert!(
            *e <= FOUR_SAMPLES_AT_MOST * off,
            "glass over edges: {e:.3} by the {} raster with 4 samples against {off:.3} without",
            v.raster.name()
        );
    }
    // Byte-identical twice; and where no glass lies, the image without the glass.
    let eight = variants[0];
    let outputs = common::render_each(&scene, &[eight, eight]);
    assert_eq!(common::max_difference(&outputs[0], &outputs[1]), (0, 0), "two renders with layers differ");
    let bare = common::render(glass_over_edges(false), RenderSettings { transparency: None, ..eight });
    let with_layers = view("transparency-layers");
    let counts = common::render(scene.clone(), RenderSettings { debug_view: with_layers, ..eight });
    let (mut outside, mut differ) = (0, 0);
    for (i, c) in counts.rgba.chunks(4).enumerate() {
        // The layer view paints the pixels without layers one colour (the count 0's), that of
        // the top-left corner, which only the wall covers.
        if c != &counts.rgba[0..4] {
            continue;
        }
        outside += 1;
        if outputs[0].rgba[4 * i..4 * i + 3] != bare.rgba[4 * i..4 * i + 3] {
            differ += 1;
        }
    }
    println!("{outside} pixels without layers, {differ} of them different from the view without the glass");
    assert!(outside > 1000, "the layer view found {outside} pixels without layers");
    assert_eq!(differ, 0, "pixels without layers changed");
}

/// A metal floor (roughness 0.3) under a normal map of grain: each of its 1,024² texels
/// tilted at random (slopes about ±0.25 each way), seen from 2.5 m at 60° below the horizon,
/// where a pixel covers about 6×6 texels (the map's third mip level) and the reference's one
/// under one; 48 lights 0.3 to 1.2 m above it. Unfiltered, each highlight is a cloud of glints.
fn grainy_metal() -> Scene {
    const SIZE: u32 = 1024;
    let mut grain = rand_chacha::ChaCha8Rng::seed_from_u64(56);
    // A sum of four uniform values: about normal, within ±0.87.
    let mut slope = || (0..4).map(|_| grain.random_range(-1.0..1.0f32)).sum::<f32>() * 0.2165;
    let normal_map: Vec<u8> = (0..SIZE * SIZE)
        .flat_map(|_| {
            let n = Vec3::new(slope(), slope(), 1.0).normalize() * 0.5 + 0.5;
            [n.x, n.y, n.z, 1.0].map(|c| (c * 255.0).round() as u8)
        })
        .collect();
    let mut w = GltfWriter::new();
    let texture = w.texture(png(SIZE, SIZE, &normal_map), "image/png");
    let metal = w.material([0.9, 0.85, 0.8, 1.0], 1.0, 0.3);
    w.json["materials"][metal]["normalTexture"] = json!({ "index": texture });
    let mesh = w.mesh(&[PrimitiveData { material: Some(metal), ..quad() }]);
    w.node(json!({ "mesh": mesh, "scale": [1.6, 1.6, 1.6] }), true);
    let (mut scene, _) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    scene.camera = Camera::looking_at(Vec3::new(0.0, 2.2, 1.2), Vec3::new(0.0, 0.0, -0.1), 50.0, 0.1, 20.0);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(57);
    lit(scene, &mut rng, 48, (Vec3::new(-1.6, 0.3, -1.6), Vec3::new(1.6, 1.2, 1.6)), 0.06..0.24, 1.0..2.0)
}

#[test]
fn highlights_under_a_grainy_normal_map_do_not_sparkle() {
    let scene = grainy_metal();
    // The reference lights the map's own normals, 64 a pixel: what a pixel's highlight should
    // be the mean of (specular anti-aliasing off, as in the image it is measured against).
    let off = RenderSettings { shading: ShadingModel::Pbr, specular_aa: false, ..visibility(160, 120, Antialiasing::Off) };
    let on = RenderSettings { specular_aa: true, ..off };
    let variants = [on, meshes(Technique::Forward, on, Antialiasing::Off), meshes(Technique::DeferredClustered, on, Antialiasing::Off)];
    let (e_off, e, outputs) = errors("grainy metal", &scene, off, &variants);
    println!("specular anti-aliasing: RMS error {e_off:.3} without, {:.3} with ({:.2} of it)", e[0], e[0] / e_off);
    assert!(e[0] <= 0.6 * e_off, "{:.3} with specular anti-aliasing against {e_off:.3} without", e[0]);
    // Every technique lights the same spread: the forward pass and the G-buffer's deferred
    // lighting as the visibility technique does (the G-buffer rounds its textures' factors to
    // 8 bits: without specular anti-aliasing its sharp glints differ by up to 7/255).
    for (v, out) in variants[1..].iter().zip(&outputs[1..]) {
        let (worst, pixels) = common::max_difference(&outputs[0], out);
        println!("{}: {pixels} pixels differ from the visibility technique's, by up to {worst}/255", v.technique.name());
        assert!(worst <= 2, "{}: {pixels} pixels differ from the visibility technique's, by up to {worst}/255", v.technique.name());
    }
}
