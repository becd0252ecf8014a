//! The compute raster draws what the hardware draws (docs/DESIGN.md#compute-raster): on
//! random scenes (low cameras, the floor crossing the near plane), the seed scene of every
//! object kind, the bench scene and a textured glTF scene, the visibility technique with the
//! compute raster and with the hardware gives the same triangle id on at least 99.9 % of the
//! covered pixels, every pixel where they differ lies where the two triangles they name
//! meet, and the shaded images differ by more than 1/255 nowhere else — both with the large
//! triangles drawn in compute too (`compute`) and by the hardware (`hybrid`). A
//! screen-covering mesh of shared-edge triangles is drawn watertight: every pixel exactly
//! once, whichever way the compute raster splits it between threads, bins and the thread
//! that finds a triangle when the bin list is full. Validation (with synchronization
//! validation) stays silent.

use crate::common;
use crate::common::view;

use glam::{Mat4, Quat, Vec3};
use ml_cpu::camera::Camera;
use ml_cpu::gltf_writer::{png, quad, GltfWriter, PrimitiveData};
use ml_cpu::lights::LightParams;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::mesh::{Mesh, Vertex};
use ml_cpu::random_scene::random_scene;
use ml_cpu::scene::{Object, Scene};
use ml_render::{CullStats, DebugView, LargeTriangles, Raster, RenderOutput, RenderSettings, Renderer, ShadingModel, Technique};
use ml_vk::Context;
use rand::{Rng, SeedableRng};
use serde_json::json;

const W: u32 = 160;
const H: u32 = 96;

/// What two rasterisers drew: ids (the triangles view) and shaded images, hardware first.
struct Drawn<'a> {
    ids: [&'a RenderOutput; 2],
    shaded: [&'a RenderOutput; 2],
}

/// What a rasteriser drew: the triangles view and the shaded image.
/// One renderer for both: the debug view changes passes, not the scene's resources.
fn draw(ctx: &Context, scene: &Scene, base: RenderSettings, raster: Raster) -> [RenderOutput; 2] {
    let settings = |debug_view| RenderSettings { raster, debug_view, ..base };
    let mut renderer = Renderer::new(ctx, scene.clone(), settings(view("triangles"))).expect("renderer");
    let ids = renderer.render().expect("render");
    assert!(renderer.reconfigure(settings(DebugView::NONE)).expect("reconfigure"), "a debug view needs a new renderer");
    [ids, renderer.render().expect("render")]
}

/// Whether `colour` is one of the 8 neighbours of (x, y) in `out`.
fn next_to(out: &RenderOutput, (x, y): (i64, i64), colour: [u8; 3]) -> bool {
    (-1..=1).any(|dy| (-1..=1).any(|dx| (dx, dy) != (0, 0) && common::pixel_at(out, x + dx, y + dy) == Some(colour)))
}

/// Covered pixels, and those whose ids differ; panics where the differences break the rules.
fn compare(what: &str, d: &Drawn, background: [u8; 3]) -> (usize, usize) {
    let [hw, cp] = d.ids;
    let (mut covered, mut differing) = (0, 0);
    let mut stray = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let (a, b) = (common::pixel(hw, x, y), common::pixel(cp, x, y));
            covered += usize::from(a != background || b != background);
            if a == b {
                let shaded = [common::pixel(d.shaded[0], x, y), common::pixel(d.shaded[1], x, y)];
                let diff = shaded[0].iter().zip(shaded[1]).map(|(p, q)| p.abs_diff(q)).max().unwrap();
                assert!(diff <= 1, "{what}: pixel ({x}, {y}) shows one triangle but its shaded colours differ by {diff}/255");
                continue;
            }
            differing += 1;
            // Where the two triangles meet: each one's triangle is next to the pixel in the other's image.
            let at = (x as i64, y as i64);
            if !(next_to(hw, at, b) || next_to(cp, at, a)) {
                stray.push((x, y));
            }
        }
    }
    println!("{what}: {differing} of {covered} covered pixels differ");
    assert!(covered > 0, "{what}: nothing drawn");
    assert!(stray.is_empty(), "{what}: ids differ away from any edge between the two triangles at {stray:?}");
    assert!(differing * 1000 <= covered, "{what}: {differing} of {covered} covered pixels differ (more than 0.1 %)");
    (covered, differing)
}

/// The colour of pixels no triangle covers, in the triangles view.
fn background(ctx: &Context) -> [u8; 3] {
    let empty = Scene::new(Vec::new(), Vec::new(), Camera::seed());
    let s = RenderSettings { debug_view: view("triangles"), ..RenderSettings::new(Technique::Visibility, 8, 8) };
    let out = Renderer::new(ctx, empty, s).unwrap().render().unwrap();
    common::pixel(&out, 4, 4)
}

/// A random scene on a floor, seen from among its objects: triangles of every size, the
/// floor's crossing the near plane (left to the hardware).
fn low_random_scene(seed: u64) -> Scene {
    let mut scene = random_scene(seed, 64).with_floor();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let eye = Vec3::new(rng.random_range(-9.0..9.0), rng.random_range(0.2..3.0), rng.random_range(-9.0..9.0));
    let target = Vec3::new(rng.random_range(-6.0..6.0), 0.0, rng.random_range(-6.0..6.0));
    scene.camera = Camera::looking_at(eye, target, 60.0, 0.1, 200.0);
    scene
}

/// Textured quads at random angles from a glTF file (pbr shading, texture sampling).
fn textured_gltf_scene() -> Scene {
    let mut w = GltfWriter::new();
    let texels: Vec<u8> = (0..16 * 16).flat_map(|i: u32| [(i * 37 % 256) as u8, (i * 91 % 256) as u8, (i * 13 % 256) as u8, 255]).collect();
    let texture = w.texture(png(16, 16, &texels), "image/png");
    let material = w.textured_material(Some(texture), None);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    for i in 0..12 {
        let mesh = w.mesh(&[PrimitiveData { material: Some(material), ..quad() }]);
        let rotation = Quat::from_euler(glam::EulerRot::XYZ, rng.random_range(0.3..2.8), rng.random_range(-1.0..1.0), 0.0);
        let at = [(i % 4) as f32 * 2.2 - 3.3, (i / 4) as f32 * 2.2 - 2.2, rng.random_range(-1.0..1.0)];
        w.node(json!({ "mesh": mesh, "translation": at, "rotation": rotation.to_array() }), true);
    }
    let camera = w.camera(json!({ "type": "perspective", "perspective": { "yfov": 0.9, "znear": 0.1, "zfar": 100.0 } }));
    w.node(json!({ "camera": camera, "translation": [0.0, 0.0, 9.0] }), true);
    let (scene, _) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    scene
}

#[test]
fn the_compute_raster_draws_the_hardwares_triangles() {
    let ctx = common::pooled_context();
    let bg = background(&ctx);
    let base = RenderSettings::new(Technique::Visibility, W, H);
    let split = Raster::DEFAULT_SPLIT;
    let mut scenes: Vec<(String, Scene, RenderSettings, u32)> = Vec::new();
    for seed in 0..2 {
        scenes.push((format!("random scene {seed}"), low_random_scene(seed), base, split));
    }
    // The seed scene close up: the kinds the random scenes lack, and the teapot's many small
    // triangles (the other kinds' seed scenes added 12 renders, half a minute of CI, and no
    // triangle the random scenes do not already draw).
    for kind in [MeshKind::Teapot, MeshKind::Cube, MeshKind::Room] {
        let scene = Scene::seed(kind, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap();
        scenes.push((format!("seed scene, {}", kind.name()), scene, base, split));
    }
    scenes.push(("bench scene".into(), ml_cpu::bench_scene::bench_scene(1000, 1, 60).unwrap(), base, split));
    // Its quads' triangles are ~20 pixels: the largest split draws them in compute.
    let pbr = RenderSettings { shading: ShadingModel::Pbr, ..base };
    scenes.push(("textured glTF".into(), textured_gltf_scene(), pbr, Raster::MAX_SPLIT));
    let (mut covered, mut differing, mut large) = ([0; 2], [0; 2], 0);
    for (what, scene, settings, split) in &scenes {
        let hardware = draw(&ctx, scene, *settings, Raster::Hardware);
        for (k, raster) in [Raster::hybrid(*split), Raster::compute(*split)].into_iter().enumerate() {
            let other = draw(&ctx, scene, *settings, raster);
            let drawn = Drawn { ids: [&hardware[0], &other[0]], shaded: [&hardware[1], &other[1]] };
            let c = *drawn.ids[1].stats.feature::<CullStats>().expect("culling stats");
            assert!(c.compute_triangles > 0, "{what}: the {} raster drew nothing in compute", raster.name());
            large += c.large_triangles;
            let (n, d) = compare(&format!("{what}, {} raster", raster.name()), &drawn, bg);
            (covered[k], differing[k]) = (covered[k] + n, differing[k] + d);
        }
    }
    for (k, name) in ["hybrid", "compute"].iter().enumerate() {
        let (d, n) = (differing[k], covered[k]);
        println!("all scenes, {name} raster: {d} of {n} covered pixels differ ({:.4} %)", 100.0 * d as f64 / n as f64);
    }
    // The random scenes' floors and the bench scene's are large and cross the near plane.
    assert!(large > 0, "no large triangle was drawn in compute");
}

/// A plane of `cols` × `rows` cells in front of `camera`, reaching 8 pixels past every side of
/// a `W`×`H` image: interior vertices moved at random by up to a fifth of a cell (edges of
/// every slope, never folding a cell over) or, every third where one is that near, onto a
/// pixel centre (edges and corners through centres: the fill rule decides), each cell split
/// along a random diagonal; front faces towards the camera.
fn screen_mesh(camera: &Camera, (cols, rows): (u32, u32), seed: u64) -> Mesh {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let inverse = (camera.projection(W as f32 / H as f32) * camera.view()).inverse();
    let (cell_w, cell_h) = ((W + 16) as f32 / cols as f32, (H + 16) as f32 / rows as f32);
    let mut vertices = Vec::new();
    for j in 0..=rows {
        for i in 0..=cols {
            let mut p = glam::Vec2::new(-8.0 + i as f32 * cell_w, -8.0 + j as f32 * cell_h);
            let interior = i > 0 && j > 0 && i < cols && j < rows;
            let reach = glam::Vec2::new(cell_w, cell_h) * 0.2;
            let centre = p.floor() + 0.5;
            if interior && rng.random_range(0..3) == 0 && (centre - p).abs().cmple(reach).all() {
                p = centre;
            } else if interior {
                p += glam::Vec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)) * reach;
            }
            // The pixel's ray met with the plane z = 0.
            let ndc = p / glam::Vec2::new(W as f32, H as f32) * 2.0 - 1.0;
            let (near, far) = (inverse.project_point3(ndc.extend(0.0)), inverse.project_point3(ndc.extend(1.0)));
            let world = near + (far - near) * (near.z / (near.z - far.z));
            vertices.push(Vertex {
                position: [world.x, world.y, 0.0],
                normal: [0.0, 0.0, 1.0],
                uv: [0.0; 2],
                tangent: [1.0, 0.0, 0.0, 1.0],
            });
        }
    }
    let at = |i: u32, j: u32| j * (cols + 1) + i;
    let mut indices = Vec::new();
    for j in 0..rows {
        for i in 0..cols {
            // Top-left, top-right, bottom-left, bottom-right on screen; counter-clockwise seen from +z.
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
            if rng.random_bool(0.5) {
                indices.extend([a, c, b, b, c, d]);
            } else {
                indices.extend([a, c, d, a, d, b]);
            }
        }
    }
    Mesh { vertices, indices }
}

#[test]
fn a_screen_of_shared_edges_is_drawn_watertight() {
    let ctx = common::pooled_context();
    let bg = background(&ctx);
    let camera = Camera::looking_at(Vec3::new(0.0, 0.0, 0.8), Vec3::ZERO, 60.0, 0.1, 10.0);
    for (seed, cells) in [(1, (40, 24)), (2, (97, 61)), (3, (23, 11))] {
        let mut scene = Scene::new(Vec::new(), Vec::new(), camera);
        scene.meshes.push(screen_mesh(&camera, cells, seed));
        let white = Material::named("white").unwrap();
        scene.objects.push(Object { transform: Mat4::IDENTITY, ..Object::placed(MeshKind::Loaded(0), Vec3::ZERO, 1.0, white) });
        let base = RenderSettings { debug_view: view("triangles"), ..RenderSettings::new(Technique::Visibility, W, H) };
        // Every triangle in compute: each pixel counted once, none left empty.
        // About a cell: the jittered triangles fall on both sides of it.
        let split = ((W + 16) as f32 / cells.0 as f32).max((H + 16) as f32 / cells.1 as f32).ceil() as u32;
        let bins = |bin_list| Raster::Compute { split, large: LargeTriangles::Bins { bin_list, grows: false } };
        // Every triangle in compute — a thread each; split between threads and bins; nearly
        // all by bins (a split of 1 pixel); nearly all in place (a list of 3 bins): each
        // pixel counted once, none left empty.
        let ways = [
            ("threads", Raster::compute(Raster::MAX_SPLIT)),
            ("threads and bins", Raster::compute(split)),
            ("bins", Raster::compute(1)),
            ("in place", bins(3)),
        ];
        for (how, raster) in ways {
            let out = Renderer::new(&ctx, scene.clone(), RenderSettings { raster, ..base }).unwrap().render().unwrap();
            let c = *out.stats.feature::<CullStats>().unwrap();
            let holes = (0..W * H).filter(|i| common::pixel(&out, i % W, i / W) == bg).count();
            println!(
                "{cells:?} cells, {how}: {} triangles a thread each, {} by {} bins, {} in place; {} pixels covered, {holes} holes",
                c.compute_triangles, c.large_triangles, c.bins, c.in_place, c.compute_pixels
            );
            assert_eq!(c.compute_triangles + c.large_triangles, c.triangles, "every triangle drawn in compute");
            match how {
                "threads" => assert_eq!(c.large_triangles, 0),
                "in place" => {
                    assert!(c.in_place > 0 && c.in_place < c.large_triangles, "{cells:?} cells: the list's overflow path is taken")
                }
                _ => assert!(c.large_triangles > 0 && c.in_place == 0, "{cells:?} cells, {how}: bins are drawn"),
            }
            assert_eq!(holes, 0, "{cells:?} cells, {how}: pixels no triangle covered");
            assert_eq!(
                c.compute_pixels,
                (W * H) as u64,
                "{cells:?} cells, {how}: pixels covered more than once (no holes, so the excess is double coverage)"
            );
        }
        // The hybrid raster: the seams between compute and hardware leave no hole either.
        let mixed = Renderer::new(&ctx, scene, RenderSettings { raster: Raster::hybrid(split), ..base }).unwrap().render().unwrap();
        let c = *mixed.stats.feature::<CullStats>().unwrap();
        assert!(c.compute_triangles > 0 && c.compute_triangles < c.triangles, "{cells:?} cells: both rasterisers draw");
        let holes = (0..W * H).filter(|i| common::pixel(&mixed, i % W, i / W) == bg).count();
        assert_eq!(holes, 0, "{cells:?} cells: pixels neither rasteriser covered");
    }
}

/// Large-triangle lists too short for a frame grow for the slot's next frames, and a render's
/// last frame, or an image sequence's frames from the first that overflowed, are drawn again
/// with them grown: each image is the one lists long enough from the start give, byte for byte (drawn in place, a triangle is one thread's loop, which a CPU
/// driver may cut short: a near view of a forest lost part of its ground so).
#[test]
fn lists_too_short_grow_and_frames_that_overflowed_are_drawn_again() {
    let ctx = common::pooled_context();
    let camera = Camera::looking_at(Vec3::new(0.0, 0.0, 0.8), Vec3::ZERO, 60.0, 0.1, 10.0);
    let mut scene = Scene::new(Vec::new(), Vec::new(), camera);
    scene.meshes.push(screen_mesh(&camera, (40, 24), 1));
    let white = Material::named("white").unwrap();
    scene.objects.push(Object { transform: Mat4::IDENTITY, ..Object::placed(MeshKind::Loaded(0), Vec3::ZERO, 1.0, white) });
    let base = RenderSettings { debug_view: view("triangles"), ..RenderSettings::new(Technique::Visibility, W, H) };
    // A split of 1 pixel: every triangle large, listed by the bins of its box.
    let lists = |bin_list, grows| Raster::Compute { split: 1, large: LargeTriangles::Bins { bin_list, grows } };
    let render = |raster, frames| Renderer::new(&ctx, scene.clone(), RenderSettings { raster, frames, ..base }).unwrap().render().unwrap();
    let long_enough = render(Raster::compute(1), 1);
    let c = *long_enough.stats.feature::<CullStats>().unwrap();
    assert!(c.large_triangles > 100 && c.in_place == 0 && long_enough.stats.redraws == 0, "{c:?}");
    // One frame, or two (one a slot): the last frame drawn again. Three: the last is the
    // first slot's second, drawn with the lists its first frame grew.
    for (frames, redraws) in [(1, 1), (2, 1), (3, 0)] {
        let grown = render(lists(16, true), frames);
        let g = *grown.stats.feature::<CullStats>().unwrap();
        println!(
            "{frames} frame(s): {} large triangles in {} bins, lists of {}, {} redrawn",
            g.large_triangles, g.bins, g.large_list, grown.stats.redraws
        );
        if redraws > 0 {
            // The statistics are the redrawn frame's.
            assert!(g.in_place == 0 && g.large_list as u64 >= g.bins.max(g.large_triangles), "{frames} frame(s): the lists grew: {g:?}");
        }
        assert_eq!(grown.stats.redraws, redraws, "{frames} frame(s): the last frame drawn again where it overflowed");
        assert_eq!(common::max_difference(&grown, &long_enough), (0, 0), "{frames} frame(s): the image of lists long enough");
    }
    // Fixed lists stay as they are: drawn in place, not again.
    let fixed = render(lists(16, false), 3);
    let f = *fixed.stats.feature::<CullStats>().unwrap();
    assert!(f.in_place > 0 && f.large_list == 16 && fixed.stats.redraws == 0, "{f:?}");
    assert_eq!(common::max_difference(&fixed, &long_enough), (0, 0), "drawn in place: the same image");
    // Two triangles over a larger image: a box of 245,760 pixels is more than lavapipe lets one
    // invocation loop (65,535 iterations in all), so drawn in place it loses its last rows.
    let mut two = scene.clone();
    two.meshes[0] = screen_mesh(&camera, (1, 1), 1);
    let large = RenderSettings { debug_view: view("triangles"), ..RenderSettings::new(Technique::Visibility, 4 * W, 4 * H) };
    let render = |raster| Renderer::new(&ctx, two.clone(), RenderSettings { raster, ..large }).unwrap().render().unwrap();
    let (grown, long_enough) = (render(lists(1, true)), render(Raster::compute(1)));
    assert_eq!(grown.stats.redraws, 1);
    assert_eq!(common::max_difference(&grown, &long_enough), (0, 0), "two triangles: the image of lists long enough");
    // An image sequence: the first frame of each slot overflows its lists. Found when the
    // first slot comes round, the frames from its first on are drawn again with lists grown
    // (every slot's), so no image handed over is one drawn in place.
    let mut sequence = common::Frames::default();
    let settings = RenderSettings { raster: lists(1, true), frames: 3, ..large };
    let output = Renderer::new(&ctx, two.clone(), settings).unwrap().render_into(&mut sequence).unwrap();
    assert_eq!(sequence.0.len(), 3, "each frame's image, once");
    for (i, image) in sequence.0.iter().enumerate() {
        assert_eq!(common::rgba_difference(image, &long_enough.rgba), (0, 0), "frame {i}: the image of lists long enough");
    }
    assert_eq!(output.stats.redraws, 1, "drawn again from the first frame, once");
}
