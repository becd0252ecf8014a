//! Scene files (docs/scenes.md#scene-files-toml): the committed `scenes/seed.toml` renders the
//! built-in seed scene's image (docs/DESIGN.md#the-seed-scene), through the same renderer
//! (≤ 1/255; measured: identical).

use crate::common;
use crate::common::view;

use ml_cpu::lights::LightParams;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::Scene;
use ml_cpu::scene_file;
use std::path::Path;

#[test]
fn the_seed_scene_file_renders_the_seed_scene() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/seed.toml");
    let file = scene_file::load(&path).expect("scenes/seed.toml");
    let seed = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap();
    let settings = common::settings(160, 90);
    let outputs = [common::render(file.scene, settings), common::render(seed, settings)];
    let (max, differing) = common::max_difference(&outputs[0], &outputs[1]);
    println!("scene file vs built-in: max {max}/255, {differing} pixels differ");
    assert!(max <= 1, "the scene file's image differs by {max}/255");
    // Not a blank frame: the spheres are lit.
    assert!(outputs[0].rgba.chunks_exact(4).filter(|p| p[0] > 60).count() > 200);
}

/// A glTF file made by our writer: three quads of three colours, each placed by its own node
/// (turned to face the camera, moved, scaled unevenly, one a child of another), seen by the
/// file's camera. The albedo view shows each colour where the CPU projects its quad's centre,
/// and the background elsewhere; the shaded image is lit where the point light is.
#[test]
fn gltf_nodes_place_their_coloured_quads() {
    use glam::Vec3;
    use ml_cpu::gltf_writer::{quad, GltfWriter, PrimitiveData};
    use ml_render::{DebugView, RenderSettings, ShadingModel, Technique};
    use serde_json::json;
    let mut w = GltfWriter::new();
    let colours = [[1.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]];
    let meshes: Vec<usize> = colours
        .iter()
        .map(|&c| {
            let m = w.material(c, 0.0, 0.8);
            w.mesh(&[PrimitiveData { material: Some(m), ..quad() }])
        })
        .collect();
    // A quarter turn about +X: the quad's +Y normal turns to +Z, towards the camera.
    let turn = [std::f32::consts::FRAC_1_SQRT_2, 0.0, 0.0, std::f32::consts::FRAC_1_SQRT_2];
    let blue = w.node(json!({ "mesh": meshes[2], "translation": [0.0, 0.0, 3.0] }), false);
    w.node(json!({ "mesh": meshes[0], "translation": [-3.0, 0.0, 0.0], "rotation": turn, "scale": [0.8, 1.0, 1.6] }), true);
    w.node(json!({ "mesh": meshes[1], "translation": [3.0, 0.0, 0.0], "rotation": turn, "children": [blue] }), true);
    let camera = w.camera(json!({ "type": "perspective", "perspective": { "yfov": 1.2, "znear": 0.1, "zfar": 100.0 } }));
    w.node(json!({ "camera": camera, "translation": [0.0, 0.0, 10.0] }), true);
    let light = w.light(json!({ "type": "point", "intensity": 40.0, "range": 30.0 }));
    w.node(json!({ "translation": [0.0, 0.0, 6.0], "extensions": { "KHR_lights_punctual": { "light": light } } }), true);
    let (scene, warnings) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    assert!(warnings.is_empty(), "{warnings:?}");
    const SIZE: u32 = 128;
    let mut albedo = RenderSettings::new(Technique::Forward, SIZE, SIZE);
    albedo.shading = ShadingModel::Pbr;
    albedo.debug_view = view("gbuffer-albedo");
    let shaded = RenderSettings { debug_view: DebugView::NONE, technique: Technique::DeferredCompute, ..albedo };
    let outputs = common::render_each(&scene, &[albedo, shaded]);
    let view_proj = scene.camera.projection(1.0) * scene.camera.view();
    // The blue quad's node is the green node's child: its +z offset turns with the parent to −y.
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let parent = glam::Mat4::from_rotation_translation(glam::Quat::from_xyzw(half, 0.0, 0.0, half), Vec3::new(3.0, 0.0, 0.0));
    let blue_centre = parent.transform_point3(Vec3::new(0.0, 0.0, 3.0));
    for (centre, expected) in
        [(Vec3::new(-3.0, 0.0, 0.0), [255, 0, 0]), (Vec3::new(3.0, 0.0, 0.0), [0, 255, 0]), (blue_centre, [0, 0, 255])]
    {
        let ndc = view_proj.project_point3(centre);
        let (x, y) = (((ndc.x + 1.0) * 0.5 * SIZE as f32) as u32, ((ndc.y + 1.0) * 0.5 * SIZE as f32) as u32);
        assert_eq!(common::pixel(&outputs[0], x, y), expected, "quad at {centre} (pixel {x}, {y})");
        // Lit: clearly brighter than the ambient term alone.
        let lit = common::pixel(&outputs[1], x, y);
        assert!(lit.iter().map(|&c| c as u32).sum::<u32>() > 150, "quad at {centre} is dark: {lit:?}");
    }
    // Between the red and green quads: background.
    let gap = view_proj.project_point3(Vec3::new(0.0, 2.5, 0.0));
    let (x, y) = (((gap.x + 1.0) * 0.5 * SIZE as f32) as u32, ((gap.y + 1.0) * 0.5 * SIZE as f32) as u32);
    assert_eq!(common::pixel(&outputs[0], x, y), [5, 5, 5]);
}

/// glTF textures on quads facing the camera (turned a quarter about +X): a base-colour
/// texture shows its four colours in the four quarters (albedo view), and a normal map that
/// tilts the normal 30° towards +u (+x in the world) shows that normal (normal view) and
/// makes the quad brighter under a light on its +x side than the same quad without it — and
/// darker under a light on its −x side.
#[test]
fn gltf_textures_colour_and_bend_their_quads() {
    use glam::{Mat4, Quat, Vec3};
    use ml_cpu::gltf_writer::{png, quad, quarters, GltfWriter, PrimitiveData};
    use ml_render::{DebugView, RenderSettings, ShadingModel, Technique};
    use serde_json::json;
    const SIZE: u32 = 128;
    let turn = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let build = |light_x: f32| {
        let mut w = GltfWriter::new();
        let checker = w.texture(png(4, 4, &quarters()), "image/png");
        let bump = w.texture(png(1, 1, &[191, 128, 238, 255]), "image/png");
        let materials = [w.textured_material(Some(checker), None), w.textured_material(None, Some(bump)), w.textured_material(None, None)];
        for (m, x) in materials.iter().zip([-3.0f32, 0.0, 3.0]) {
            let mesh = w.mesh(&[PrimitiveData { material: Some(*m), ..quad() }]);
            w.node(json!({ "mesh": mesh, "translation": [x, 0.0, 0.0], "rotation": turn.to_array() }), true);
        }
        let camera = w.camera(json!({ "type": "perspective", "perspective": { "yfov": 1.0, "znear": 0.1, "zfar": 100.0 } }));
        w.node(json!({ "camera": camera, "translation": [0.0, 0.0, 8.0] }), true);
        let light = w.light(json!({ "type": "point", "intensity": 3.0, "range": 12.0 }));
        w.node(json!({ "translation": [light_x, 0.0, 1.5], "extensions": { "KHR_lights_punctual": { "light": light } } }), true);
        ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file").0
    };
    let scene = build(0.0);
    let settings = |view: DebugView, technique: Technique| {
        let mut s = RenderSettings::new(technique, SIZE, SIZE);
        s.shading = ShadingModel::Pbr;
        s.debug_view = view;
        s
    };
    let outputs = common::render_each(
        &scene,
        &[settings(view("gbuffer-albedo"), Technique::Forward), settings(view("gbuffer-normal"), Technique::Deferred)],
    );
    let view_proj = scene.camera.projection(1.0) * scene.camera.view();
    let pixel_at = |x: f32, object_point: Vec3| {
        let world = Mat4::from_rotation_translation(turn, Vec3::new(x, 0.0, 0.0)).transform_point3(object_point);
        let ndc = view_proj.project_point3(world);
        (((ndc.x + 1.0) * 0.5 * SIZE as f32) as u32, ((ndc.y + 1.0) * 0.5 * SIZE as f32) as u32)
    };
    // The quad's (x, z) ↦ uv ((x + 1) / 2, (z + 1) / 2): texel (i, j) is around x, z = ±0.5.
    for ((u, v), colour) in
        [((-0.5, -0.5), [255, 0, 0]), ((0.5, -0.5), [0, 255, 0]), ((-0.5, 0.5), [0, 0, 255]), ((0.5, 0.5), [255, 255, 255])]
    {
        let (px, py) = pixel_at(-3.0, Vec3::new(u, 0.0, v));
        assert_eq!(common::pixel(&outputs[0], px, py), colour, "texel at object ({u}, {v}), pixel ({px}, {py})");
    }
    // The bent normal (0.5, 0, 0.866) in the normal view (n·0.5 + 0.5), deferred.
    let (px, py) = pixel_at(0.0, Vec3::ZERO);
    let shown = common::pixel(&outputs[1], px, py);
    for (got, want) in shown.iter().zip([191u8, 128, 238]) {
        assert!(got.abs_diff(want) <= 2, "normal-mapped quad shows {shown:?}, expected ≈ [191, 128, 238]");
    }
    let (flat_x, flat_y) = pixel_at(3.0, Vec3::ZERO);
    let plain = common::pixel(&outputs[1], flat_x, flat_y);
    assert!(plain[0].abs_diff(128) <= 1 && plain[1].abs_diff(128) <= 1 && plain[2] == 255, "the plain quad faces +z: {plain:?}");
    // Lit from its +x side, the bent quad is brighter than with the light on its −x side; the
    // plain quad (lit symmetrically) sets the scale.
    let brightness = |light_x: f32, quad_x: f32| {
        let s = build(light_x);
        let out = common::render(s, settings(DebugView::NONE, Technique::Forward));
        let (px, py) = pixel_at(quad_x, Vec3::ZERO);
        common::pixel(&out, px, py).iter().map(|&c| c as u32).sum::<u32>()
    };
    let (towards, away) = (brightness(1.5, 0.0), brightness(-1.5, 0.0));
    println!("bent quad: light towards its normal {towards}, away {away}");
    assert!(towards > away + 60, "the normal map should turn the quad towards +x: {towards} vs {away}");
}
