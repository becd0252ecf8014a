//! Alpha masks and double-sided materials (glTF `alphaMode`, `alphaCutoff`, `doubleSided`;
//! docs/scenes.md): every scene here is a glTF file our writer makes, with quads cut by
//! `gltf_writer::cutout` (a plate with two round holes and a slot, in no symmetric pattern), and checked against a CPU ray cast
//! that cuts with `ml_cpu::alpha_mask::kept` — the base level of the texture, filtered as its
//! sampler says, times the base colour factor's alpha, against the material's cutoff (BLEND:
//! 0.5). A pixel is "sure" when the rays through it and its 8 neighbours' centres all meet the
//! same object (so it is more than a pixel from any cut edge or silhouette); pixels that are
//! not sure are "edge" pixels, where two rasterisers (or two alpha filters' roundings) may
//! decide a boundary differently.
//!
//! - every technique × shading model equals forward on a grid of masked quads (some seen from
//!   behind, two modelled with both faces on shared vertices, as foliage exporters write
//!   leaves) over a floor under 256 lights, but at counted edge pixels; so do the visibility
//!   technique's compute and hybrid rasters and its culling off;
//! - the albedo view shows, at every sure pixel, the object the CPU sees there: holes show
//!   what is behind them (the floor, another quad, a cube hidden behind a plate but for a
//!   hole — which GPU occlusion culling must not drop), plates show the quad;
//! - factors and modes: a factor alpha below the cutoff removes the quad, OPAQUE ignores the
//!   texture's alpha, BLEND cuts at 0.5 with a warning naming the material;
//! - shadows have the holes: the blinn-phong sun (graphics and compute shadow maps) and
//!   point-light shadows (copy, direct, layered, multiview where it works, compute, atlas);
//! - single-sided quads seen from behind draw nothing; double-sided ones are drawn and lit on
//!   the side the camera sees, exactly as the same quad turned to face the camera.

use crate::common;
use crate::common::view;

use glam::{Quat, Vec2, Vec3, Vec4};
use ml_cpu::alpha_mask::kept;
use ml_cpu::blinn_phong::shadow_view_proj;
use ml_cpu::camera::Camera;
use ml_cpu::gltf_writer::{cutout, png, quad, GltfWriter, PrimitiveData, CUTOUT_SIZE};
use ml_cpu::gpu_types::PointLight;
use ml_cpu::scene::{AlphaMode, Scene};
use ml_render::settings::{multiview_depth_is_broken, AtlasSettings};
use ml_render::SHADOW_MAP_SIZE;
use ml_render::{
    DebugView, OmniShadowMode, OmniShadowSettings, Raster, RenderOutput, RenderSettings, ShadingModel, SunShadowMode, Technique,
};
use ml_vk::{Context, ContextDesc};
use rand::{Rng, SeedableRng};
use serde_json::json;

/// glTF sampler filter: nearest.
const NEAREST: u32 = 9728;

/// Most edge pixels (beyond the tolerance, all at cut edges or silhouettes) an image may have
/// against its reference: 1 % of its pixels.
const MAX_EDGE_FRACTION: f32 = 0.01;

/// blinn-phong's sun shadow in the paths that rebuild the position from depth (deferred,
/// deferred-clustered, deferred-compute, visibility; tests/gpu/techniques.rs SHADOW_OUTLIERS): the
/// moved position may flip a shadow-map comparison near its threshold, on a few lit pixels
/// anywhere (measured here: 3 or 4 of 19,200, by 3–15/255, on plates and the floor; none with
/// the sun off). Counted, and at most this many an image.
const SHADOW_OUTLIERS: usize = 8;

// ---------------------------------------------------------------------------------------------
// Scenes
// ---------------------------------------------------------------------------------------------

/// The writer's quad (+Y normal) stood up facing +Z, then turned `yaw_deg` about +Y (180:
/// facing −Z, away from a camera on +Z).
fn standing(yaw_deg: f32) -> Quat {
    Quat::from_rotation_y(yaw_deg.to_radians()) * Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)
}

/// A quad of `material` placed by a node.
fn add_quad(w: &mut GltfWriter, material: usize, at: Vec3, rotation: Quat, scale: Vec3) {
    add_primitive(w, PrimitiveData { material: Some(material), ..quad() }, at, rotation, scale);
}

fn add_primitive(w: &mut GltfWriter, primitive: PrimitiveData, at: Vec3, rotation: Quat, scale: Vec3) {
    let mesh = w.mesh(&[primitive]);
    w.node(json!({ "mesh": mesh, "translation": at.to_array(), "rotation": rotation.to_array(), "scale": scale.to_array() }), true);
}

/// The quad modelled with both faces, as foliage exporters write double-sided leaves: each
/// triangle also present reversed on the same vertices (sharing their normal, so one face's
/// normal points against its winding), the reversed ones first.
fn twin_faced_quad(material: usize) -> PrimitiveData {
    let q = quad();
    let Some((indices, ty)) = q.indices else { unreachable!("the quad is indexed") };
    let mut twins: Vec<u32> = indices.chunks_exact(3).flat_map(|t| [t[0], t[2], t[1]]).collect();
    twins.extend(indices);
    PrimitiveData { indices: Some((twins, ty)), material: Some(material), ..q }
}

/// An opaque, single-sided floor: the quad at y = 0 facing up, `half` to each side.
fn add_floor(w: &mut GltfWriter, albedo: [f32; 3], half: f32) {
    let m = w.material([albedo[0], albedo[1], albedo[2], 1.0], 0.0, 0.8);
    // Scaled evenly: its box (each mesh's [−1, 1]³, scene bounds) then holds anything within
    // `half` of the origin, so moving an object about inside it keeps the sun's shadow map.
    add_quad(w, m, Vec3::ZERO, Quat::IDENTITY, Vec3::splat(half));
}

/// The cut-out texture, white (a material's albedo is then its factor), default sampler.
fn cutout_texture(w: &mut GltfWriter) -> usize {
    w.texture(png(CUTOUT_SIZE, CUTOUT_SIZE, &cutout([255, 255, 255])), "image/png")
}

/// Load the file; lights and camera are the test's (`light_motion` 0: the lights stay where
/// they are put).
fn load(w: &GltfWriter, camera: Camera, lights: Vec<PointLight>) -> (Scene, Vec<String>) {
    let (mut scene, warnings) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    scene.camera = camera;
    scene.lights = lights;
    scene.cones.clear();
    scene.light_motion = 0.0;
    (scene, warnings)
}

fn light(at: Vec3, radius: f32, colour: f32) -> PointLight {
    PointLight { position_radius: [at.x, at.y, at.z, radius], color: [colour, colour, colour, 0.0] }
}

/// `count` lights at random in the box [lo, hi], radii and strengths at random.
fn random_lights(seed: u64, count: usize, (lo, hi): (Vec3, Vec3), radii: (f32, f32), strength: f32) -> Vec<PointLight> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..count)
        .map(|_| {
            let p = Vec3::new(rng.random_range(lo.x..hi.x), rng.random_range(lo.y..hi.y), rng.random_range(lo.z..hi.z));
            let c = [0; 3].map(|_| rng.random_range(0.2..1.0f32) * strength);
            PointLight { position_radius: [p.x, p.y, p.z, rng.random_range(radii.0..radii.1)], color: [c[0], c[1], c[2], 0.0] }
        })
        .collect()
}

const GRID_W: u32 = 160;
const GRID_H: u32 = 120;

/// The grid: nine masked quads standing in three rows over an opaque floor, each its own
/// colour and material — MASK at the default cutoff, MASK at 0.3 with factor alpha 0.45 (still
/// kept), BLEND (a mask at 0.5), MASK through a nearest-filtered sampler (of the cut-out
/// mirrored) — all double-sided,
/// turned every way (four of them seen from behind), two modelled with both faces
/// (`twin_faced_quad`: one seen from the front, one from behind); a small cube hidden behind the middle
/// plate but for one of its holes; 256 random lights.
fn grid_scene() -> (Scene, Vec<String>) {
    let mut w = GltfWriter::new();
    let linear = cutout_texture(&mut w);
    // The nearest-filtered plates' holes mirrored: another texture, another pattern (the
    // alpha of each texture is found where it is, not where another one's is).
    let mut mirrored = cutout([255, 255, 255]);
    for row in mirrored.chunks_exact_mut(4 * CUTOUT_SIZE as usize) {
        let texels: Vec<[u8; 4]> = row.chunks_exact(4).rev().map(|t| [t[0], t[1], t[2], t[3]]).collect();
        row.copy_from_slice(texels.as_flattened());
    }
    let nearest = w.texture(png(CUTOUT_SIZE, CUTOUT_SIZE, &mirrored), "image/png");
    w.sampler(nearest, json!({ "magFilter": NEAREST, "minFilter": NEAREST }));
    add_floor(&mut w, [0.5, 0.5, 0.5], 7.0);
    let colours = [
        [0.9, 0.2, 0.1],
        [0.2, 0.8, 0.1],
        [0.1, 0.3, 0.9],
        [0.9, 0.8, 0.1],
        [0.8, 0.1, 0.8],
        [0.9, 0.5, 0.3],
        [0.4, 0.9, 0.5],
        [0.5, 0.3, 0.9],
        [0.95, 0.95, 0.95],
    ];
    let yaws = [0.0, 180.0, 30.0, 205.0, 0.0, -40.0, 180.0, 15.0, 160.0];
    for (i, (c, yaw)) in colours.iter().zip(yaws).enumerate() {
        let m = match i % 4 {
            0 => w.alpha_material(Some(linear), [c[0], c[1], c[2], 1.0], "MASK", None, true),
            1 => w.alpha_material(Some(linear), [c[0], c[1], c[2], 0.45], "MASK", Some(0.3), true),
            2 => w.alpha_material(Some(linear), [c[0], c[1], c[2], 0.8], "BLEND", None, true),
            _ => w.alpha_material(Some(nearest), [c[0], c[1], c[2], 1.0], "MASK", None, true),
        };
        w.material_name(m, &format!("plate-{i}"));
        if i == 8 {
            transform_texture(&mut w, m);
        }
        let (col, row) = ((i % 3) as f32 - 1.0, (i / 3) as f32 - 1.0);
        let at = Vec3::new(col * 3.0, 1.3, row * 3.0);
        if i == 0 || i == 3 {
            add_primitive(&mut w, twin_faced_quad(m), at, standing(yaw), Vec3::ONE);
        } else {
            add_quad(&mut w, m, at, standing(yaw), Vec3::ONE);
        }
    }
    // Behind the middle plate (i = 4, facing +Z), where its large hole at uv (0.28, 0.28) is
    // (object (−0.44, −0.44): world (−0.44, 1.74, 0)), on the camera's line through it.
    let cube = w.material([0.1, 0.9, 0.9, 1.0], 0.0, 0.5);
    let mesh = w.mesh(&[ml_cpu::gltf_writer::mesh_primitive(&ml_cpu::mesh::cube(1.0), Some(cube))]);
    w.node(json!({ "mesh": mesh, "translation": [-0.53, 1.57, -0.6], "scale": [0.2, 0.2, 0.2] }), true);
    let camera = Camera::looking_at(Vec3::new(1.0, 4.5, 10.0), Vec3::new(0.0, 1.0, 0.0), 45.0, 0.1, 60.0);
    let lights = random_lights(11, 256, (Vec3::new(-6.0, 0.1, -6.0), Vec3::new(6.0, 3.5, 6.0)), (1.0, 3.0), 0.8);
    load(&w, camera, lights)
}

// ---------------------------------------------------------------------------------------------
// The CPU's view: a ray cast that cuts with alpha_mask::kept
// ---------------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug)]
struct Hit {
    object: usize,
    t: f32,
    point: Vec3,
}

/// Every triangle of the scene in world space, with its object and texture coordinates.
struct Tracer<'a> {
    scene: &'a Scene,
    triangles: Vec<(usize, [Vec3; 3], [Vec2; 3])>,
}

impl<'a> Tracer<'a> {
    fn new(scene: &'a Scene) -> Tracer<'a> {
        let mut triangles = Vec::new();
        for (i, o) in scene.objects.iter().enumerate() {
            let mesh = scene.mesh(o.mesh).expect("the object's mesh");
            for t in mesh.indices.chunks_exact(3) {
                let v = [0, 1, 2].map(|k| mesh.vertices[t[k] as usize]);
                triangles.push((i, v.map(|v| o.transform.transform_point3(Vec3::from(v.position))), v.map(|v| Vec2::from(v.uv))));
            }
        }
        Tracer { scene, triangles }
    }

    /// The nearest surface the ray meets that is there: its front (or either side where
    /// double-sided; `both_sides` makes every object so) and, where `alpha`, not cut out.
    fn cast(&self, origin: Vec3, dir: Vec3, alpha: bool, both_sides: bool) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for &(object, [a, b, c], [ua, ub, uc]) in &self.triangles {
            let (e1, e2) = (b - a, c - a);
            let pv = dir.cross(e2);
            let det = e1.dot(pv);
            if det.abs() < 1e-12 {
                continue;
            }
            let tv = origin - a;
            let u = tv.dot(pv) / det;
            let qv = tv.cross(e1);
            let v = dir.dot(qv) / det;
            let t = e2.dot(qv) / det;
            if u < 0.0 || v < 0.0 || u + v > 1.0 || t <= 1e-4 || best.is_some_and(|h| h.t <= t) {
                continue;
            }
            let o = &self.scene.objects[object];
            let front = e1.cross(e2).dot(dir) < 0.0;
            if !front && !o.extras.double_sided && !both_sides {
                continue;
            }
            let uv = ua * (1.0 - u - v) + ub * u + uc * v;
            if alpha && !kept(o, &self.scene.textures, uv) {
                continue;
            }
            best = Some(Hit { object, t, point: origin + dir * t });
        }
        best
    }
}

/// The camera ray through sub-pixel position (x, y) of a width × height image.
fn ray(camera: &Camera, x: f32, y: f32, (w, h): (u32, u32)) -> (Vec3, Vec3) {
    let inv = (camera.projection(w as f32 / h as f32) * camera.view()).inverse();
    let (nx, ny) = (x / w as f32 * 2.0 - 1.0, y / h as f32 * 2.0 - 1.0);
    let unproject = |z: f32| {
        let p = inv * Vec4::new(nx, ny, z, 1.0);
        p.truncate() / p.w
    };
    let near = unproject(0.0);
    (near, (unproject(1.0) - near).normalize())
}

/// What the CPU sees through each pixel's centre (and one pixel around the image).
struct CpuView {
    size: (u32, u32),
    hits: Vec<Option<Hit>>,
}

impl CpuView {
    fn new(tracer: &Tracer, size: (u32, u32), alpha: bool, both_sides: bool) -> CpuView {
        let (w, h) = size;
        let mut hits = Vec::with_capacity(((w + 2) * (h + 2)) as usize);
        for y in -1..=h as i64 {
            for x in -1..=w as i64 {
                let (o, d) = ray(&tracer.scene.camera, x as f32 + 0.5, y as f32 + 0.5, size);
                hits.push(tracer.cast(o, d, alpha, both_sides));
            }
        }
        CpuView { size, hits }
    }

    fn hit(&self, x: i64, y: i64) -> Option<Hit> {
        self.hits[((y + 1) * (self.size.0 as i64 + 2) + x + 1) as usize]
    }

    fn object(&self, x: u32, y: u32) -> Option<usize> {
        self.hit(x as i64, y as i64).map(|h| h.object)
    }

    /// Whether the pixel and its 8 neighbours see the same object (or all nothing).
    fn sure(&self, x: u32, y: u32) -> bool {
        let id = self.object(x, y);
        (-1..=1).all(|dy| (-1..=1).all(|dx| self.hit(x as i64 + dx, y as i64 + dy).map(|h| h.object) == id))
    }

    fn pixels(&self) -> impl Iterator<Item = (u32, u32)> {
        let (w, h) = self.size;
        (0..h).flat_map(move |y| (0..w).map(move |x| (x, y)))
    }
}

// ---------------------------------------------------------------------------------------------
// Comparisons
// ---------------------------------------------------------------------------------------------

/// The techniques' tolerance against forward (tests/gpu/techniques.rs): 2/255 where the position
/// is rebuilt from depth, else 1/255.
fn tolerance(t: Technique) -> u8 {
    if t.lights_in_compute() || t.lights_in_subpass() {
        2
    } else {
        1
    }
}

fn difference(a: &RenderOutput, b: &RenderOutput, x: u32, y: u32) -> u8 {
    common::pixel(a, x, y).iter().zip(common::pixel(b, x, y)).map(|(p, q)| p.abs_diff(q)).max().unwrap()
}

/// What a comparison against a reference found.
#[derive(Debug, Default)]
struct Compared {
    /// Largest channel difference anywhere.
    max: u8,
    /// Pixels beyond the tolerance at edges (not sure), and elsewhere.
    edge: usize,
    other: Vec<(u32, u32, u8)>,
}

fn compare(reference: &RenderOutput, out: &RenderOutput, allowed: u8, cpu: &CpuView) -> Compared {
    let mut c = Compared::default();
    for (x, y) in cpu.pixels() {
        let d = difference(reference, out, x, y);
        c.max = c.max.max(d);
        if d > allowed {
            if cpu.sure(x, y) {
                c.other.push((x, y, d));
            } else {
                c.edge += 1;
            }
        }
    }
    c
}

/// Beyond the tolerance only at edges (at most MAX_EDGE_FRACTION of the image), or at no more
/// than `outliers` other pixels.
fn assert_same_but_edges(what: &str, reference: &RenderOutput, out: &RenderOutput, allowed: u8, cpu: &CpuView, outliers: usize) {
    let c = compare(reference, out, allowed, cpu);
    let pixels = (out.width * out.height) as usize;
    println!("{what}: max {}/255; beyond {allowed}/255: {} edge pixels, {} others {:?}", c.max, c.edge, c.other.len(), c.other);
    assert!(c.other.len() <= outliers, "{what}: pixels away from any cut edge differ (x, y, by): {:?}", &c.other[..c.other.len().min(12)]);
    assert!(c.edge as f32 <= pixels as f32 * MAX_EDGE_FRACTION, "{what}: {} edge pixels differ beyond {allowed}/255", c.edge);
}

/// The albedo view's value of linear albedo `a` (gamma 1/2.2; the cut-out texture is white).
fn albedo_view(a: Vec3) -> [u8; 3] {
    a.to_array().map(|c| (c.powf(1.0 / 2.2) * 255.0).round() as u8)
}

/// At every sure pixel where the CPU sees an object, the albedo view shows its albedo (within
/// 2/255): holes show what is behind them, plates their quad. Returns the pixels checked.
fn assert_albedo_is_the_cpus(what: &str, scene: &Scene, out: &RenderOutput, cpu: &CpuView) -> usize {
    assert_view_is_the_cpus(what, out, cpu, |object| albedo_view(scene.objects[object].material.albedo))
}

/// At every sure pixel where the CPU sees an object, the image shows `view(object)` (within
/// 2/255). Returns the pixels checked.
fn assert_view_is_the_cpus(what: &str, out: &RenderOutput, cpu: &CpuView, view: impl Fn(usize) -> [u8; 3]) -> usize {
    let mut wrong = Vec::new();
    let mut checked = 0;
    for (x, y) in cpu.pixels().filter(|&(x, y)| cpu.sure(x, y)) {
        let Some(object) = cpu.object(x, y) else { continue };
        let want = view(object);
        let got = common::pixel(out, x, y);
        checked += 1;
        if got.iter().zip(want).any(|(g, w)| g.abs_diff(w) > 2) {
            wrong.push(((x, y), object, got, want));
        }
    }
    println!("{what}: checked at {checked} sure pixels, {} wrong", wrong.len());
    assert!(
        wrong.is_empty(),
        "{what}: {} sure pixels show another surface than the CPU's ((x, y), object, shown, expected): {:?}",
        wrong.len(),
        &wrong[..wrong.len().min(10)]
    );
    checked
}

fn with(t: Technique, shading: ShadingModel, view: DebugView, (w, h): (u32, u32)) -> RenderSettings {
    let mut s = RenderSettings::new(t, w, h);
    s.shading = shading;
    s.debug_view = view;
    // Two frames: both frames in flight, and the visibility technique's early phase drawing
    // what the first frame found visible.
    s.frames = if t == Technique::Forward { 1 } else { 2 };
    s
}

// ---------------------------------------------------------------------------------------------
// a. Every technique and shading model equals forward
// ---------------------------------------------------------------------------------------------

#[test]
fn a_masked_grid_is_the_same_in_every_technique_and_shading_model() {
    let (scene, warnings) = grid_scene();
    assert!(!warnings.iter().any(|w| w.contains("BLEND")), "BLEND is blended, not a loader warning: {warnings:?}");
    let tracer = Tracer::new(&scene);
    let cpu = CpuView::new(&tracer, (GRID_W, GRID_H), true, false);
    let edges = cpu.pixels().filter(|&(x, y)| !cpu.sure(x, y)).count();
    println!("grid: {edges} of {} pixels are edge pixels", GRID_W * GRID_H);
    for model in [ShadingModel::Seed, ShadingModel::BlinnPhong, ShadingModel::Pbr] {
        let settings: Vec<RenderSettings> = Technique::ALL.iter().map(|&t| with(t, model, DebugView::NONE, (GRID_W, GRID_H))).collect();
        let out = common::render_each(&scene, &settings);
        let lit = out[0].rgba.chunks_exact(4).filter(|p| p[0].max(p[1]).max(p[2]) > 40).count();
        let saturated = out[0].rgba.chunks_exact(4).filter(|p| p[0].max(p[1]).max(p[2]) == 255).count();
        println!("{}: {lit} pixels lit above 40/255, {saturated} saturated", model.name());
        assert!(lit > 2000, "{}: the lights light too little ({lit} pixels)", model.name());
        for (o, t) in out.iter().zip(Technique::ALL).skip(1) {
            // Without the sun's shadow map every technique, twin-faced plates included, is
            // within 1/255 of forward (measured: 1 at most where the position is rebuilt).
            let (allowed, outliers) = match model {
                ShadingModel::BlinnPhong => (tolerance(t), if tolerance(t) == 2 { SHADOW_OUTLIERS } else { 0 }),
                _ => (1, 0),
            };
            assert_same_but_edges(&format!("grid {} {}", model.name(), t.name()), &out[0], o, allowed, &cpu, outliers);
        }
    }
}

/// The visibility technique's rasterisers (hardware, hybrid, compute) and its culling (on,
/// off) give the same image: the compute raster cuts by the same alpha, and culling never
/// drops what a hole shows.
#[test]
fn a_masked_grid_is_the_same_through_every_raster_and_without_culling() {
    let (scene, _) = grid_scene();
    let tracer = Tracer::new(&scene);
    let cpu = CpuView::new(&tracer, (GRID_W, GRID_H), true, false);
    for model in [ShadingModel::Seed, ShadingModel::Pbr] {
        let base = with(Technique::Visibility, model, DebugView::NONE, (GRID_W, GRID_H));
        let variants = [
            ("hardware, culling off", RenderSettings { culling: false, ..base }),
            ("hybrid", RenderSettings { raster: Raster::hybrid(Raster::DEFAULT_SPLIT), ..base }),
            ("compute", RenderSettings { raster: Raster::compute(Raster::DEFAULT_SPLIT), ..base }),
            ("compute, culling off", RenderSettings { raster: Raster::compute(Raster::DEFAULT_SPLIT), culling: false, ..base }),
        ];
        let mut settings = vec![base];
        settings.extend(variants.iter().map(|v| v.1));
        let out = common::render_each(&scene, &settings);
        for (o, (name, _)) in out[1..].iter().zip(&variants) {
            assert_same_but_edges(&format!("visibility {} {name} vs hardware", model.name()), &out[0], o, 1, &cpu, 0);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// b. Against the CPU
// ---------------------------------------------------------------------------------------------

/// Every technique (and the visibility technique's three rasters) shows, at every sure pixel,
/// the albedo of the object the CPU sees there — through the holes of plates seen from either
/// side, the nearest-filtered ones included, and the cube that only a hole shows.
#[test]
fn b_every_sure_pixel_shows_what_the_cpu_sees() {
    let (scene, _) = grid_scene();
    let tracer = Tracer::new(&scene);
    let cpu = CpuView::new(&tracer, (GRID_W, GRID_H), true, false);
    // Through holes: sure pixels where the plates, were they opaque, would hide what is seen.
    let opaque = CpuView::new(&tracer, (GRID_W, GRID_H), false, false);
    let through = cpu.pixels().filter(|&(x, y)| cpu.sure(x, y) && opaque.object(x, y) != cpu.object(x, y)).count();
    let cube = scene.objects.len() - 1;
    let cube_seen = cpu.pixels().filter(|&(x, y)| cpu.sure(x, y) && cpu.object(x, y) == Some(cube)).count();
    let cube_in_plain_sight = opaque.pixels().filter(|&(x, y)| opaque.object(x, y) == Some(cube)).count();
    println!(
        "{through} sure pixels see through a hole; the cube fills {cube_seen} sure pixels, none without the holes ({cube_in_plain_sight})"
    );
    assert!(through > 300, "only {through} pixels see through holes");
    assert!(cube_seen >= 4 && cube_in_plain_sight == 0, "the cube should show through a hole only: {cube_seen}, {cube_in_plain_sight}");
    let mut settings: Vec<RenderSettings> =
        Technique::ALL.iter().map(|&t| with(t, ShadingModel::Pbr, view("gbuffer-albedo"), (GRID_W, GRID_H))).collect();
    let vis = *settings.last().unwrap();
    settings.push(RenderSettings { raster: Raster::hybrid(Raster::DEFAULT_SPLIT), ..vis });
    settings.push(RenderSettings { raster: Raster::compute(Raster::DEFAULT_SPLIT), ..vis });
    let names: Vec<String> =
        Technique::ALL.iter().map(|t| t.name().to_owned()).chain(["visibility hybrid".into(), "visibility compute".into()]).collect();
    let out = common::render_each(&scene, &settings);
    for (o, name) in out.iter().zip(&names) {
        let checked = assert_albedo_is_the_cpus(&format!("grid albedo {name}"), &scene, o, &cpu);
        assert!(checked > 5000, "{name}: only {checked} pixels checked");
    }
}

/// The alpha debug view colours each surface by its alpha mode (opaque grey, masked green,
/// blended orange; double-sided brighter) at every sure pixel, in every technique and raster.
#[test]
fn the_alpha_view_shows_each_surfaces_mode() {
    let (scene, _) = grid_scene();
    let tracer = Tracer::new(&scene);
    let cpu = CpuView::new(&tracer, (GRID_W, GRID_H), true, false);
    let expected = |object: usize| {
        let x = &scene.objects[object].extras;
        let display = match x.alpha_mode {
            AlphaMode::Blend => Vec3::new(1.0, 0.5, 0.1),
            AlphaMode::Mask { .. } => Vec3::new(0.2, 0.9, 0.2),
            AlphaMode::Opaque => Vec3::splat(0.45),
        } * if x.double_sided { 1.0 } else { 0.7 };
        display.to_array().map(|c| (c * 255.0).round() as u8)
    };
    let kinds: std::collections::BTreeSet<String> = scene.objects.iter().map(|o| format!("{:?}", o.extras.alpha_mode)).collect();
    assert!(kinds.len() >= 3, "the grid should hold opaque, masked and blended surfaces: {kinds:?}");
    let mut settings: Vec<RenderSettings> =
        Technique::ALL.iter().map(|&t| with(t, ShadingModel::Pbr, view("alpha"), (GRID_W, GRID_H))).collect();
    let vis = *settings.last().unwrap();
    settings.push(RenderSettings { raster: Raster::compute(Raster::DEFAULT_SPLIT), ..vis });
    for (o, s) in common::render_each(&scene, &settings).iter().zip(&settings) {
        let checked = assert_view_is_the_cpus(&format!("alpha view {} {:?}", s.technique.name(), s.raster), o, &cpu, expected);
        assert!(checked > 5000, "only {checked} pixels checked");
    }
}

const ROW_W: u32 = 240;
const ROW_H: u32 = 80;

/// What a quad of the row is: (name, alphaMode, alphaCutoff, factor alpha, whether it has the
/// cut-out texture, whether it is drawn at all, whether it has holes).
type RowQuad = (&'static str, &'static str, Option<f32>, f32, bool, bool, bool);

const ROW: [RowQuad; 7] = [
    ("mask", "MASK", None, 1.0, true, true, true),
    ("mask-faint", "MASK", None, 0.45, true, false, false),
    ("mask-low-cutoff", "MASK", Some(0.3), 0.45, true, true, true),
    ("blend-kept", "BLEND", None, 0.6, true, true, true),
    ("blend-faint", "BLEND", None, 0.4, true, false, false),
    ("opaque", "OPAQUE", None, 0.2, true, true, false),
    ("untextured-faint", "MASK", Some(0.5), 0.3, false, false, false),
];

/// A wall and a floor, and in front of the wall the row of quads (each its own colour,
/// facing the camera). `quads` false leaves the quads out.
fn row_scene(quads: bool) -> (Scene, Vec<String>) {
    let mut w = GltfWriter::new();
    let texture = cutout_texture(&mut w);
    add_floor(&mut w, [0.5, 0.5, 0.5], 8.0);
    let wall = w.material([0.2, 0.6, 0.9, 1.0], 0.0, 0.8);
    add_quad(&mut w, wall, Vec3::new(0.0, 2.0, -2.0), standing(0.0), Vec3::new(8.0, 1.0, 2.0));
    if quads {
        let colours =
            [[0.9, 0.2, 0.1], [0.9, 0.8, 0.1], [0.8, 0.1, 0.8], [0.2, 0.8, 0.1], [0.9, 0.5, 0.3], [0.95, 0.95, 0.95], [0.9, 0.3, 0.6]];
        for (i, ((name, mode, cutoff, alpha, textured, _, _), c)) in ROW.iter().zip(colours).enumerate() {
            let m = w.alpha_material(textured.then_some(texture), [c[0], c[1], c[2], *alpha], mode, *cutoff, false);
            w.material_name(m, name);
            add_quad(&mut w, m, Vec3::new((i as f32 - 3.0) * 1.9, 1.2, 0.0), standing(0.0), Vec3::splat(0.9));
        }
    }
    let camera = Camera::looking_at(Vec3::new(0.0, 1.5, 9.0), Vec3::new(0.0, 1.2, 0.0), 30.0, 0.1, 60.0);
    let lights = random_lights(5, 64, (Vec3::new(-7.0, 0.2, -1.5), Vec3::new(7.0, 3.0, 3.0)), (1.0, 3.0), 0.6);
    let (mut scene, warnings) = load(&w, camera, lights);
    scene.ambient = 0.3;
    (scene, warnings)
}

/// A row of quads in front of a wall: through a hole, every technique shows exactly what the
/// scene without the quads shows; the alpha factor multiplies the texture's alpha (0.45 is cut
/// at 0.5 entirely, kept at 0.3) and alone decides without a texture; BLEND, where the render
/// does not blend it (the library's `transparency: None`; shadows always), is a mask at 0.5;
/// OPAQUE keeps the holes filled.
#[test]
fn b_holes_show_what_is_behind_and_factors_and_modes_cut_as_the_file_says() {
    let (scene, warnings) = row_scene(true);
    let (bare, _) = row_scene(false);
    println!("{warnings:?}");
    assert!(!warnings.iter().any(|w| w.contains("BLEND")), "{warnings:?}");
    assert!(!warnings.iter().any(|w| w.contains("'mask") || w.contains("'opaque'")), "{warnings:?}");
    let tracer = Tracer::new(&scene);
    let cpu = CpuView::new(&tracer, (ROW_W, ROW_H), true, false);
    let opaque = CpuView::new(&tracer, (ROW_W, ROW_H), false, false);
    // Objects: floor 0, wall 1, then the row.
    let quad_of = |object: Option<usize>| object.and_then(|o| o.checked_sub(2));
    let mut shown = [0usize; ROW.len()];
    let mut holes = [0usize; ROW.len()];
    let mut hidden = [0usize; ROW.len()];
    for (x, y) in cpu.pixels().filter(|&(x, y)| cpu.sure(x, y) && opaque.sure(x, y)) {
        match (quad_of(opaque.object(x, y)), quad_of(cpu.object(x, y))) {
            (Some(q), Some(p)) if p == q => shown[q] += 1,
            (Some(q), None) if ROW[q].6 => holes[q] += 1,
            (Some(q), None) => hidden[q] += 1,
            _ => {}
        }
    }
    println!("per quad, sure pixels showing it {shown:?}, its holes {holes:?}, hidden wholly {hidden:?}");
    for (i, (name, _, _, _, _, drawn, has_holes)) in ROW.iter().enumerate() {
        assert_eq!(shown[i] > 100, *drawn, "{name}: {} pixels show it", shown[i]);
        assert_eq!(holes[i] > 40, *has_holes, "{name}: {} hole pixels", holes[i]);
        assert_eq!(hidden[i] > 100, !drawn, "{name}");
    }
    let settings: Vec<RenderSettings> =
        Technique::ALL.iter().map(|&t| with(t, ShadingModel::Seed, DebugView::NONE, (ROW_W, ROW_H))).collect();
    let albedo: Vec<RenderSettings> =
        Technique::ALL.iter().map(|&t| with(t, ShadingModel::Pbr, view("gbuffer-albedo"), (ROW_W, ROW_H))).collect();
    let out = common::render_each(&scene, &[settings.clone(), albedo].concat());
    let without = common::render_each(&bare, &settings);
    for (i, t) in Technique::ALL.into_iter().enumerate() {
        let (o, w) = (&out[i], &without[i]);
        let (mut through, mut plate) = (Vec::new(), 0);
        for (x, y) in cpu.pixels().filter(|&(x, y)| cpu.sure(x, y) && opaque.sure(x, y)) {
            let Some(q) = quad_of(opaque.object(x, y)) else { continue };
            let d = difference(o, w, x, y);
            if quad_of(cpu.object(x, y)).is_none() {
                // A hole, or a quad cut away wholly: what is behind, exactly.
                if d > tolerance(t) {
                    through.push((ROW[q].0, x, y, d));
                }
            } else if d > 30 {
                plate += 1;
            }
        }
        let plates: usize = shown.iter().sum();
        println!(
            "{}: {} through-pixels differ from the scene without quads; {plate} of {plates} plate pixels differ from it by > 30/255",
            t.name(),
            through.len()
        );
        assert!(
            through.is_empty(),
            "{}: through a hole the scene behind differs (quad, x, y, by): {:?}",
            t.name(),
            &through[..through.len().min(12)]
        );
        assert!(plate * 10 >= plates * 9, "{}: only {plate} of {plates} plate pixels show the plate", t.name());
        assert_albedo_is_the_cpus(&format!("row albedo {}", t.name()), &scene, &out[Technique::ALL.len() + i], &cpu);
    }
}

// ---------------------------------------------------------------------------------------------
// c. Shadows through the holes
// ---------------------------------------------------------------------------------------------

const SHADOW_SIZE: u32 = 96;

/// A floor, and a masked plate (single-sided, facing up) at `plate_y` above it, `half` to a
/// side (hole radius 0.3125 · half).
/// Give material `m`'s base colour texture a KHR_texture_transform (moved, turned a little,
/// its holes shifted: every pass must cut where the CPU, which applies it, says).
fn transform_texture(w: &mut GltfWriter, m: usize) {
    let transform = json!({ "offset": [0.1, 0.05], "rotation": 0.2, "scale": [1.1, 0.95] });
    w.json["materials"][m]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = json!({ "KHR_texture_transform": transform });
    w.json["extensionsUsed"] = json!(["KHR_texture_transform"]);
}

fn plate_scene(camera: Camera, lights: Vec<PointLight>, plate_y: f32, half: f32, floor: f32) -> Scene {
    let mut w = GltfWriter::new();
    let texture = cutout_texture(&mut w);
    add_floor(&mut w, [0.8, 0.8, 0.8], floor);
    let m = w.alpha_material(Some(texture), [0.9, 0.4, 0.2, 1.0], "MASK", None, false);
    transform_texture(&mut w, m);
    add_quad(&mut w, m, Vec3::new(0.0, plate_y, 0.0), Quat::IDENTITY, Vec3::new(half, 1.0, half));
    load(&w, camera, lights).0
}

/// Where a floor pixel's light comes from: `toward(p)` gives the direction to the light and
/// how far it is; the answer is sure if every point within `margin(p)` of p on the floor
/// agrees. Returns per sure floor pixel: (x, y), lit, whether the light passes a hole.
fn floor_sight(
    scene: &Scene,
    size: (u32, u32),
    toward: impl Fn(Vec3) -> (Vec3, f32),
    margin: impl Fn(Vec3) -> f32,
) -> Vec<((u32, u32), bool, bool)> {
    let tracer = Tracer::new(scene);
    let cpu = CpuView::new(&tracer, size, true, false);
    let mut out = Vec::new();
    for (x, y) in cpu.pixels().filter(|&(x, y)| cpu.sure(x, y) && cpu.object(x, y) == Some(0)) {
        let p = cpu.hit(x as i64, y as i64).unwrap().point;
        let lit_at = |q: Vec3, alpha: bool| {
            let (d, far) = toward(q);
            tracer.cast(q + Vec3::Y * 1e-3, d, alpha, true).is_none_or(|h| h.t > far)
        };
        let m = margin(p);
        let around: Vec<Vec3> = std::iter::once(p)
            .chain((0..12).map(|k| k as f32 * std::f32::consts::TAU / 12.0).map(|a| p + Vec3::new(a.cos(), 0.0, a.sin()) * m))
            .collect();
        let lit = lit_at(p, true);
        if around.iter().all(|&q| lit_at(q, true) == lit) {
            out.push(((x, y), lit, lit && !lit_at(p, false)));
        }
    }
    out
}

/// At every sure floor pixel: lit ones as the reference without the occluder (`open`),
/// shadowed ones as the one without the light (`dark`), within 1/255; enough of each, and
/// enough lit through holes. Returns (lit through holes, shadowed).
fn assert_shadows(
    what: &str,
    sight: &[((u32, u32), bool, bool)],
    out: &RenderOutput,
    open: &RenderOutput,
    dark: &RenderOutput,
) -> (usize, usize) {
    let mut wrong = Vec::new();
    let (mut through, mut shadowed) = (0, 0);
    for &((x, y), lit, hole) in sight {
        let reference = if lit { open } else { dark };
        let d = difference(out, reference, x, y);
        if d > 1 {
            wrong.push(((x, y), lit, hole, common::pixel(out, x, y), common::pixel(reference, x, y)));
        }
        through += usize::from(hole);
        shadowed += usize::from(!lit);
    }
    println!("{what}: {} sure floor pixels, {through} lit through holes, {shadowed} shadowed; {} wrong", sight.len(), wrong.len());
    assert!(wrong.is_empty(), "{what}: ((x, y), lit, through a hole, shown, expected): {:?}", &wrong[..wrong.len().min(10)]);
    // The references differ where it matters: the test can fail.
    let contrast = sight.iter().filter(|(_, lit, _)| !lit).filter(|&&((x, y), _, _)| difference(open, dark, x, y) > 20).count();
    assert!(
        through >= 30 && shadowed >= 100 && contrast * 10 >= shadowed * 9,
        "{what}: too little to check ({through}, {shadowed}, {contrast})"
    );
    (through, shadowed)
}

/// blinn-phong's sun through a masked plate: floor pixels whose sun ray passes a hole are lit
/// as if the plate were not there, those behind its solid part are as dark as with the sun
/// off — the shadow map (drawn by a render pass or by the compute raster) has the holes.
#[test]
fn c_the_sun_shines_through_the_holes() {
    let sun = Vec3::new(1.0, -1.0, 0.0).normalize();
    let camera = Camera::looking_at(Vec3::new(3.5, 6.0, 3.0), Vec3::new(2.0, 0.0, 0.0), 50.0, 0.1, 100.0);
    let (plate_y, half) = (2.0, 1.2);
    let build = |plate: bool, sun_on: bool| {
        // The plate stays in the scene's bounds either way (under the floor), so the shadow
        // map's texels are the same.
        let mut s = plate_scene(camera, vec![light(Vec3::splat(100.0), 0.1, 1.0)], plate_y, half, 4.0);
        if !plate {
            s.objects[1].transform = glam::Mat4::from_translation(Vec3::new(0.0, -3.0, 0.0)) * s.objects[1].transform;
        }
        s.blinn_phong.sun_direction = sun;
        s.blinn_phong.sun_strength = Vec3::splat(if sun_on { 1.0 } else { 0.0 });
        s.blinn_phong.spot.strength = Vec3::ZERO;
        s.blinn_phong.ambient = Vec3::splat(0.1);
        s
    };
    let scenes = [build(true, true), build(false, true), build(true, false)];
    let (lo, hi) = scenes[0].bounds();
    let texel = 2.0 / shadow_view_proj(lo, hi, sun).row(0).truncate().length() / SHADOW_MAP_SIZE as f32;
    // The 3×3 filter, the bias and the alpha read at texel centres: 6 texels, √2 longer on a
    // floor the sun meets at 45°.
    let margin = 6.0 * texel * 2f32.sqrt();
    let sight = floor_sight(&scenes[0], (SHADOW_SIZE, SHADOW_SIZE), |_| (-sun, f32::INFINITY), |_| margin);
    let cases = [
        (SunShadowMode::Graphics, Technique::Forward),
        (SunShadowMode::Graphics, Technique::Deferred),
        (SunShadowMode::Graphics, Technique::Visibility),
        (SunShadowMode::Compute, Technique::Forward),
        (SunShadowMode::Compute, Technique::DeferredCompute),
        (SunShadowMode::Compute, Technique::Visibility),
    ];
    let ctx_settings: Vec<RenderSettings> = cases
        .iter()
        .map(|&(mode, t)| RenderSettings {
            sun_shadow: mode,
            ..with(t, ShadingModel::BlinnPhong, DebugView::NONE, (SHADOW_SIZE, SHADOW_SIZE))
        })
        .collect();
    let renders: Vec<Vec<RenderOutput>> = scenes.iter().map(|s| common::render_each(s, &ctx_settings)).collect();
    for (i, (mode, t)) in cases.iter().enumerate() {
        assert_shadows(&format!("sun {} {}", mode.name(), t.name()), &sight, &renders[0][i], &renders[1][i], &renders[2][i]);
    }
}

const CUBE: u32 = 256;

/// Point-light shadows through a masked plate between a light and the floor, in every way
/// the cubes (or the atlas) are drawn: floor pixels the light reaches through a hole are lit
/// as without shadows, those behind the plate's solid part as with the light off.
#[test]
fn c_point_lights_shine_through_the_holes_in_every_shadow_mode() {
    let at = Vec3::new(0.0, 3.5, 0.0);
    let lamp = light(at, 9.0, 3.0);
    let camera = Camera::looking_at(Vec3::new(0.0, 2.5, 6.5), Vec3::new(0.0, 0.0, -0.3), 50.0, 0.1, 60.0);
    let scene = plate_scene(camera, vec![lamp], 1.5, 1.2, 5.0);
    let dark = Scene { lights: vec![light(at, 9.0, 0.0)], ..scene.clone() };
    // 6 cube texels at the point's distance (the tent, the normal offset, the bias; cf.
    // common::shadow_rays), stretched on a floor the light meets obliquely.
    let margin = |p: Vec3| {
        let to = at - p;
        6.0 * to.length() * 2.0 / CUBE as f32 * to.length() / to.y
    };
    let sight = floor_sight(&scene, (SHADOW_SIZE, SHADOW_SIZE), |p| ((at - p).normalize(), (at - p).length()), margin);
    let multiview = {
        let ctx = Context::new(&ContextDesc::default()).expect("a Vulkan device");
        ctx.info.features.multiview && !multiview_depth_is_broken(&ctx)
    };
    let atlas = OmniShadowMode::Atlas(AtlasSettings { fixed_size: Some(CUBE), ..AtlasSettings::DEFAULT });
    let mut cases = vec![
        (OmniShadowMode::Copy, Technique::Forward),
        (OmniShadowMode::Direct, Technique::Deferred),
        (OmniShadowMode::Layered, Technique::ClusteredGpu),
        (OmniShadowMode::COMPUTE, Technique::Visibility),
        (OmniShadowMode::COMPUTE, Technique::ClusteredCpu),
        (atlas, Technique::DeferredCompute),
        (atlas, Technique::Forward),
    ];
    if multiview {
        cases.push((OmniShadowMode::Multiview, Technique::DeferredClustered));
    }
    let shadowed: Vec<RenderSettings> = cases
        .iter()
        .map(|&(mode, t)| RenderSettings {
            omni: Some(OmniShadowSettings { mode, lights: 1, all: false, size: CUBE }),
            ..with(t, ShadingModel::Pbr, DebugView::NONE, (SHADOW_SIZE, SHADOW_SIZE))
        })
        .collect();
    let plain: Vec<RenderSettings> = shadowed.iter().map(|s| RenderSettings { omni: None, ..*s }).collect();
    let out = common::render_each(&scene, &[shadowed, plain.clone()].concat());
    let off = common::render_each(&dark, &plain);
    for (i, (mode, t)) in cases.iter().enumerate() {
        assert_shadows(&format!("omni {} {}", mode.name(), t.name()), &sight, &out[i], &out[cases.len() + i], &off[i]);
    }
}

// ---------------------------------------------------------------------------------------------
// d. Sides
// ---------------------------------------------------------------------------------------------

const SIDE_W: u32 = 128;
const SIDE_H: u32 = 72;
const SIDE_X: [f32; 4] = [-3.3, -1.1, 1.1, 3.3];

/// Four quads standing in a row over a floor: opaque single-sided, masked single-sided,
/// opaque double-sided, masked double-sided (objects 1–4). `away`: turned away from the
/// camera (it sees their backs), else facing it and all single-sided. `single` false leaves
/// the single-sided ones out. Lights: one per quad, in front (`front`) or behind.
fn sides_scene(away: bool, single: bool, front: bool) -> Scene {
    let mut w = GltfWriter::new();
    let texture = cutout_texture(&mut w);
    add_floor(&mut w, [0.5, 0.5, 0.5], 6.0);
    let kinds = [
        (false, "OPAQUE", [0.9, 0.3, 0.2]),
        (false, "MASK", [0.2, 0.9, 0.3]),
        (true, "OPAQUE", [0.3, 0.4, 0.9]),
        (true, "MASK", [0.9, 0.8, 0.2]),
    ];
    for ((double_sided, mode, c), x) in kinds.into_iter().zip(SIDE_X) {
        if !double_sided && !single {
            continue;
        }
        let m = w.alpha_material(Some(texture), [c[0], c[1], c[2], 1.0], mode, None, double_sided && away);
        // Turned away, a point of the quad has u mirrored (1 − u) against the same point of
        // the quad facing the camera: the facing one's u is mirrored too, so the two cut the
        // same holes at the same places.
        let mut q = quad();
        if !away {
            q.uvs = q.uvs.map(|uvs| uvs.iter().map(|&[u, v]| [1.0 - u, v]).collect());
        }
        let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..q }]);
        let rotation = standing(if away { 180.0 } else { 0.0 });
        w.node(json!({ "mesh": mesh, "translation": [x, 1.2, 0.0], "rotation": rotation.to_array() }), true);
    }
    let camera = Camera::looking_at(Vec3::new(0.0, 2.0, 7.0), Vec3::new(0.0, 1.0, 0.0), 45.0, 0.1, 60.0);
    let z = if front { 1.2 } else { -1.2 };
    let lights = SIDE_X.iter().map(|&x| light(Vec3::new(x, 1.3, z), 2.5, 2.0)).collect();
    load(&w, camera, lights).0
}

/// A single-sided quad seen from behind is not drawn: the image is the one without it. A
/// double-sided one is, lit on the side the camera sees — by the light on the camera's side,
/// not by the one behind — exactly as the same quad turned to face the camera, with the
/// normal turned toward the camera (the normal view). In every technique, with pbr.
#[test]
fn d_back_faces_vanish_unless_double_sided_and_then_are_lit_from_the_camera_side() {
    let away_front = sides_scene(true, true, true);
    let tracer = Tracer::new(&away_front);
    let cpu = CpuView::new(&tracer, (SIDE_W, SIDE_H), true, false);
    let both = CpuView::new(&tracer, (SIDE_W, SIDE_H), true, true);
    let facing = sides_scene(false, true, true);
    let facing_tracer = Tracer::new(&facing);
    let facing_cpu = CpuView::new(&facing_tracer, (SIDE_W, SIDE_H), true, false);
    // Sure pixels of each double-sided quad (the CPU sees the same plate from either side),
    // and of the single-sided ones' backs.
    let double: Vec<(u32, u32)> = cpu
        .pixels()
        .filter(|&(x, y)| {
            cpu.sure(x, y)
                && facing_cpu.sure(x, y)
                && matches!(cpu.object(x, y), Some(3 | 4))
                && cpu.object(x, y) == facing_cpu.object(x, y)
        })
        .collect();
    let single: Vec<(u32, u32)> = both.pixels().filter(|&(x, y)| both.sure(x, y) && matches!(both.object(x, y), Some(1 | 2))).collect();
    println!("{} sure double-sided pixels, {} pixels of single-sided backs", double.len(), single.len());
    assert!(double.len() > 400 && single.len() > 400, "too small");
    assert!(single.iter().all(|&(x, y)| !matches!(cpu.object(x, y), Some(1 | 2))), "the CPU draws no back face");
    let scenes = [
        away_front.clone(),
        sides_scene(true, true, false),
        facing.clone(),
        sides_scene(false, true, false),
        sides_scene(true, false, true),
    ];
    // pbr alone: every model takes its normal from the same surface code, and the seed model
    // (specular only, its highlights cover little of the quads) is held to the same
    // double-sided rule by the masked grid's twin-faced plates (CI's time).
    for model in [ShadingModel::Pbr] {
        let settings: Vec<RenderSettings> = Technique::ALL.iter().map(|&t| with(t, model, DebugView::NONE, (SIDE_W, SIDE_H))).collect();
        let normals: Vec<RenderSettings> = settings.iter().map(|s| RenderSettings { debug_view: view("gbuffer-normal"), ..*s }).collect();
        let r: Vec<Vec<RenderOutput>> = scenes.iter().map(|s| common::render_each(s, &settings)).collect();
        let n = if model == ShadingModel::Pbr { common::render_each(&away_front, &normals) } else { Vec::new() };
        for (i, t) in Technique::ALL.into_iter().enumerate() {
            let what = format!("{} {}", model.name(), t.name());
            let [away_lit, away_behind, facing_lit, facing_behind, no_single] = [0, 1, 2, 3, 4].map(|k| &r[k][i]);
            // Single-sided backs: nothing drawn, anywhere.
            let (max, differing) = common::max_difference(away_lit, no_single);
            println!("{what}: single-sided backs change {differing} pixels (max {max}/255)");
            assert!(max <= 1, "{what}: a single-sided quad seen from behind is drawn ({differing} pixels, up to {max}/255)");
            // Double-sided: as the quad facing the camera, lit from the front, dark from behind.
            let (mut wrong_lit, mut wrong_dark, mut brighter) = (Vec::new(), Vec::new(), 0);
            for &(x, y) in &double {
                if difference(away_lit, facing_lit, x, y) > tolerance(t) {
                    wrong_lit.push(((x, y), common::pixel(away_lit, x, y), common::pixel(facing_lit, x, y)));
                }
                if difference(away_behind, facing_behind, x, y) > tolerance(t) {
                    wrong_dark.push(((x, y), common::pixel(away_behind, x, y), common::pixel(facing_behind, x, y)));
                }
                let luma = |o: &RenderOutput| common::pixel(o, x, y).iter().map(|&c| c as u32).sum::<u32>();
                brighter += usize::from(luma(away_lit) > luma(away_behind) + 30);
            }
            println!("{what}: double-sided backs: {} differ from the facing quad lit from the front, {} lit from behind; {brighter} of {} brighter lit from the front", wrong_lit.len(), wrong_dark.len(), double.len());
            assert!(
                wrong_lit.is_empty(),
                "{what}: a double-sided back lit from the camera's side is not the facing quad ((x, y), shown, facing): {:?}",
                &wrong_lit[..wrong_lit.len().min(8)]
            );
            assert!(
                wrong_dark.is_empty(),
                "{what}: a double-sided back lit from behind is not the facing quad lit from behind: {:?}",
                &wrong_dark[..wrong_dark.len().min(8)]
            );
            // (The seed model is specular alone: its highlights cover little of the quads.)
            if model == ShadingModel::Pbr {
                assert!(
                    brighter * 10 >= double.len() * 9,
                    "{what}: the light on the camera's side hardly lights the back ({brighter} of {})",
                    double.len()
                );
            }
            if let Some(normal) = n.get(i) {
                // World +Z, toward the camera (its back's geometric normal is −Z): (0.5, 0.5, 1).
                let wrong: Vec<_> = double
                    .iter()
                    .map(|&(x, y)| ((x, y), common::pixel(normal, x, y)))
                    .filter(|(_, p)| p[0].abs_diff(128) > 3 || p[1].abs_diff(128) > 3 || p[2] < 252)
                    .collect();
                assert!(wrong.is_empty(), "{what}: the normal view at double-sided backs is not +Z: {:?}", &wrong[..wrong.len().min(8)]);
            }
        }
    }
}
