//! glTF materials beyond base colour and normal maps (docs/scenes.md#gltf-20-files):
//! metallic-roughness, occlusion and emissive textures with their factors, texture samplers,
//! mipmaps and orthographic cameras — each rendered from a file our writer makes and checked
//! where the CPU knows the answer, through every technique (the deferred ones carry these
//! values through the G-buffer).

use crate::common;
use crate::common::view;

use glam::{Quat, Vec3};
use ml_cpu::gltf_writer::{png, quad, quarters, GltfWriter, PrimitiveData};
use ml_cpu::scene::Scene;
use ml_render::{DebugView, RenderOutput, RenderSettings, ShadingModel, Technique};
use serde_json::json;

const SIZE: u32 = 96;

/// A quarter turn about +X: the quad's +Y normal faces +Z (the camera), its texture upright.
fn facing() -> Quat {
    Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)
}

/// Quads (material, x position) in a row facing an orthographic camera on +Z that sees
/// `half_height` above and below; no lights.
fn row_of_quads(w: &mut GltfWriter, quads: &[(usize, f32)], half_height: f32, aspect: f32) -> Scene {
    for &(material, x) in quads {
        let mesh = w.mesh(&[PrimitiveData { material: Some(material), ..quad() }]);
        w.node(json!({ "mesh": mesh, "translation": [x, 0.0, 0.0], "rotation": facing().to_array() }), true);
    }
    let ortho = json!({ "xmag": half_height * aspect, "ymag": half_height, "znear": 0.1, "zfar": 50.0 });
    let camera = w.camera(json!({ "type": "orthographic", "orthographic": ortho }));
    w.node(json!({ "camera": camera, "translation": [0.0, 0.0, 10.0] }), true);
    let (scene, warnings) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    assert!(warnings.is_empty(), "{warnings:?}");
    scene
}

/// Pixel where the quad at `x` shows object point (u, 0, v), u and v in [−1, 1].
fn pixel_of(scene: &Scene, (width, height): (u32, u32), x: f32, (u, v): (f32, f32)) -> (u32, u32) {
    let world = glam::Mat4::from_rotation_translation(facing(), Vec3::new(x, 0.0, 0.0)).transform_point3(Vec3::new(u, 0.0, v));
    let ndc = (scene.camera.projection(width as f32 / height as f32) * scene.camera.view()).project_point3(world);
    (((ndc.x + 1.0) * 0.5 * width as f32) as u32, ((ndc.y + 1.0) * 0.5 * height as f32) as u32)
}

/// The object points at the centres of the quarters of `quarters()` (u right, v down).
const QUARTER_CENTRES: [(f32, f32); 4] = [(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)];

fn every_technique(shading: ShadingModel, view: DebugView, (width, height): (u32, u32)) -> Vec<RenderSettings> {
    Technique::ALL
        .into_iter()
        .map(|t| {
            let mut s = RenderSettings::new(t, width, height);
            s.shading = shading;
            s.debug_view = view;
            s
        })
        .collect()
}

fn assert_close(out: &RenderOutput, at: (u32, u32), want: [u8; 3], tolerance: u8, what: &str) {
    let got = common::pixel(out, at.0, at.1);
    assert!(got.iter().zip(want).all(|(g, w)| g.abs_diff(w) <= tolerance), "{what}: pixel {at:?} is {got:?}, expected {want:?}");
}

/// The metallic-roughness texture's green and blue multiply the material's roughness and
/// metallic: the material view shows (roughness, metallic) per quarter, in every technique.
#[test]
fn metallic_roughness_texture_sets_roughness_and_metallic() {
    let mut w = GltfWriter::new();
    let texture = w.texture(png(4, 4, &quarters()), "image/png");
    let m = w.material([0.8, 0.8, 0.8, 1.0], 1.0, 0.6);
    w.json["materials"][m]["pbrMetallicRoughness"]["metallicRoughnessTexture"] = json!({ "index": texture });
    let scene = row_of_quads(&mut w, &[(m, 0.0)], 1.2, 1.0);
    let outputs = common::render_each(&scene, &every_technique(ShadingModel::Pbr, view("gbuffer-material"), (SIZE, SIZE)));
    // Quarters red, green, blue, white: (g, b) = (0, 0), (1, 0), (0, 1), (1, 1) × (0.6, 1).
    let rough = (0.6f32 * 255.0).round() as u8;
    for (centre, want) in QUARTER_CENTRES.into_iter().zip([[0, 0, 0], [rough, 0, 0], [0, 255, 0], [rough, 255, 0]]) {
        let at = pixel_of(&scene, (SIZE, SIZE), 0.0, centre);
        for (out, t) in outputs.iter().zip(Technique::ALL) {
            assert_close(out, at, want, 1, &format!("{} at {centre:?}", t.name()));
        }
    }
}

/// Occlusion scales the ambient term (1 + strength · (texel − 1)) and emission adds the
/// emissive factor × texture, the seed model's output being clip + gamma 1/2.2: with ambient 1,
/// a white quad shows its occlusion and a black one its emission, in every technique.
#[test]
fn occlusion_darkens_ambient_light_and_emission_adds_light() {
    let mut w = GltfWriter::new();
    let texture = w.texture(png(4, 4, &quarters()), "image/png");
    let occluded = w.material([1.0; 4], 0.0, 0.5);
    w.json["materials"][occluded]["occlusionTexture"] = json!({ "index": texture, "strength": 0.5 });
    let glowing = w.material([0.0, 0.0, 0.0, 1.0], 0.0, 0.5);
    w.json["materials"][glowing]["emissiveTexture"] = json!({ "index": texture });
    w.json["materials"][glowing]["emissiveFactor"] = json!([1.0, 0.5, 0.25]);
    let mut scene = row_of_quads(&mut w, &[(occluded, -1.1), (glowing, 1.1)], 1.2, 2.0);
    scene.ambient = 1.0;
    let size = (2 * SIZE, SIZE);
    let outputs = common::render_each(&scene, &every_technique(ShadingModel::Seed, DebugView::NONE, size));
    let gamma = |linear: f32| (linear.powf(1.0 / 2.2) * 255.0).round() as u8;
    // Occlusion texel red: 1 in the red and white quarters, 0 in the others → 1 or 0.5.
    let half = gamma(0.5);
    let occlusion = [[255; 3], [half; 3], [half; 3], [255; 3]];
    // Emission: the quarter's colour × (1, 0.5, 0.25).
    let (g, b) = (gamma(0.5), gamma(0.25));
    let emission = [[255, 0, 0], [0, g, 0], [0, 0, b], [255, g, b]];
    for (i, centre) in QUARTER_CENTRES.into_iter().enumerate() {
        for (out, t) in outputs.iter().zip(Technique::ALL) {
            assert_close(out, pixel_of(&scene, size, -1.1, centre), occlusion[i], 1, &format!("{} occlusion at {centre:?}", t.name()));
            assert_close(out, pixel_of(&scene, size, 1.1, centre), emission[i], 1, &format!("{} emission at {centre:?}", t.name()));
        }
    }
}

/// glTF samplers: a 2×1 texture (red | green) on quads whose u runs from −1 to 2 repeats,
/// clamps or mirrors it as its sampler says; nearest filtering keeps the two colours apart
/// where linear filtering blends them.
#[test]
fn samplers_wrap_and_filter_as_the_file_says() {
    const NEAREST: u32 = 9728;
    const LINEAR: u32 = 9729;
    const REPEAT: u32 = 10497;
    const CLAMP: u32 = 33071;
    const MIRROR: u32 = 33648;
    let mut w = GltfWriter::new();
    let image = png(2, 1, &[255, 0, 0, 255, 0, 255, 0, 255]);
    let kinds = [(REPEAT, NEAREST), (CLAMP, NEAREST), (MIRROR, NEAREST), (CLAMP, LINEAR)];
    let xs = [-3.3, -1.1, 1.1, 3.3];
    let mut quads = Vec::new();
    for ((wrap, filter), x) in kinds.into_iter().zip(xs) {
        let t = w.texture(image.clone(), "image/png");
        w.sampler(t, json!({ "magFilter": filter, "minFilter": filter, "wrapS": wrap, "wrapT": wrap }));
        let m = w.textured_material(Some(t), None);
        // u = 1.5·(x + 1) − 1 over the quad's x ∈ [−1, 1]; v in the middle.
        let mut q = quad();
        q.uvs = Some(q.positions.iter().map(|p| [1.5 * (p[0] + 1.0) - 1.0, 0.5]).collect());
        let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..q }]);
        quads.push((mesh, x));
    }
    for &(mesh, x) in &quads {
        w.node(json!({ "mesh": mesh, "translation": [x, 0.0, 0.0], "rotation": facing().to_array() }), true);
    }
    let ortho = json!({ "xmag": 4.8, "ymag": 1.2, "znear": 0.1, "zfar": 50.0 });
    let camera = w.camera(json!({ "type": "orthographic", "orthographic": ortho }));
    w.node(json!({ "camera": camera, "translation": [0.0, 0.0, 10.0] }), true);
    let scene = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file").0;
    assert_eq!(scene.textures.len(), 4, "one image, four samplers");
    let size = (4 * SIZE, SIZE);
    let techniques = [Technique::Forward, Technique::Deferred, Technique::DeferredCompute];
    let settings: Vec<RenderSettings> = every_technique(ShadingModel::Pbr, view("gbuffer-albedo"), size)
        .into_iter()
        .filter(|s| techniques.contains(&s.technique))
        .collect();
    let outputs = common::render_each(&scene, &settings);
    let (red, green) = ([255, 0, 0], [0, 255, 0]);
    let object_x = |u: f32| (u + 1.0) / 1.5 - 1.0;
    let expected = [
        [red, green, red, green, red, green], // repeat
        [red, red, red, green, green, green], // clamp to edge
        [green, red, red, green, green, red], // mirrored repeat
    ];
    for (out, t) in outputs.iter().zip(techniques) {
        for (row, &x) in expected.iter().zip(&xs) {
            for (want, u) in row.iter().zip([-0.75, -0.25, 0.25, 0.75, 1.25, 1.75]) {
                assert_close(out, pixel_of(&scene, size, x, (object_x(u), 0.0)), *want, 0, &format!("{} quad {x} at u {u}", t.name()));
            }
        }
        // Near the texel boundary (u = 0.45): nearest shows red alone, linear a blend.
        let nearest = common::pixel(out, pixel_of(&scene, size, xs[1], (object_x(0.45), 0.0)).0, SIZE / 2);
        let linear = common::pixel(out, pixel_of(&scene, size, xs[3], (object_x(0.45), 0.0)).0, SIZE / 2);
        assert_eq!(nearest, red, "{}: nearest filtering", t.name());
        assert!(linear[0] > 150 && linear[1] > 100 && linear[2] == 0, "{}: linear filtering shows {linear:?}", t.name());
    }
}

/// An orthographic camera draws equal quads at different depths the same size (a perspective
/// one draws the farther smaller), and every technique agrees with forward on a lit scene
/// seen through it.
#[test]
fn orthographic_cameras_keep_sizes_and_every_technique_agrees() {
    let build = |orthographic: bool| {
        let mut w = GltfWriter::new();
        let m = w.material([0.9, 0.6, 0.3, 1.0], 0.2, 0.5);
        let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
        for (x, z) in [(-1.5, 0.0), (1.5, -6.0)] {
            w.node(json!({ "mesh": mesh, "translation": [x, 0.0, z], "rotation": facing().to_array() }), true);
        }
        let camera = if orthographic {
            w.camera(json!({ "type": "orthographic", "orthographic": { "xmag": 3.0, "ymag": 3.0, "znear": 0.0, "zfar": 40.0 } }))
        } else {
            w.camera(json!({ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.1, "zfar": 40.0 } }))
        };
        w.node(json!({ "camera": camera, "translation": [0.0, 0.0, 8.0] }), true);
        for (i, x) in [-2.0f32, 2.0].into_iter().enumerate() {
            let light = w.light(json!({ "type": "point", "intensity": 20.0 + 10.0 * i as f32, "range": 9.0 }));
            w.node(json!({ "translation": [x, 1.0, 2.0], "extensions": { "KHR_lights_punctual": { "light": light } } }), true);
        }
        ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file")
    };
    let ((ortho, warnings), (perspective, _)) = (build(true), build(false));
    // znear 0 cannot start logarithmic depth slices: it is moved and said so.
    assert!(warnings.len() == 1 && warnings[0].contains("znear 0"), "{warnings:?}");
    assert_eq!(ortho.camera.orthographic, Some(3.0));
    let albedo = every_technique(ShadingModel::Pbr, view("gbuffer-albedo"), (SIZE, SIZE)).remove(0);
    let covered = |scene: &Scene| {
        let out = common::render(scene.clone(), albedo);
        // Left half: the near quad; right half: the far one.
        let count = |range: std::ops::Range<u32>| {
            range.flat_map(|x| (0..SIZE).map(move |y| (x, y))).filter(|&(x, y)| common::pixel(&out, x, y)[0] > 100).count()
        };
        (count(0..SIZE / 2), count(SIZE / 2..SIZE))
    };
    let (near, far) = covered(&ortho);
    assert!(near > 500 && near.abs_diff(far) <= SIZE as usize, "orthographic: near quad {near} pixels, far quad {far}");
    let (near, far) = covered(&perspective);
    assert!(far * 2 < near, "perspective: near quad {near} pixels, far quad {far}");
    let outputs = common::render_each(&ortho, &every_technique(ShadingModel::Pbr, DebugView::NONE, (SIZE, SIZE)));
    let lit = outputs[0].rgba.chunks_exact(4).filter(|p| p[0] > 80).count();
    assert!(lit > 500, "the lights light the quads: {lit} bright pixels");
    for (out, t) in outputs.iter().zip(Technique::ALL).skip(1) {
        let (max, differing) = common::max_difference(&outputs[0], out);
        assert!(max <= 1, "{} differs from forward by {max}/255 at {differing} pixels", t.name());
    }
}

/// Mipmaps: a 64×64 checker of red and green texels on a quad 12 pixels wide is sampled from
/// its mip levels, each texel of which (above level 0) is exactly half red, half green — so
/// the albedo view shows the blend everywhere inside the quad, not the checker's aliasing.
#[test]
fn a_minified_texture_is_read_from_its_mipmaps() {
    let mut w = GltfWriter::new();
    let checker: Vec<u8> =
        (0..64 * 64).flat_map(|i| if (i % 64 + i / 64) % 2 == 0 { [255, 0, 0, 255] } else { [0, 255, 0, 255] }).collect();
    let texture = w.texture(png(64, 64, &checker), "image/png");
    let m = w.textured_material(Some(texture), None);
    let scene = row_of_quads(&mut w, &[(m, 0.0)], 8.0, 1.0);
    let settings: Vec<RenderSettings> = every_technique(ShadingModel::Pbr, view("gbuffer-albedo"), (SIZE, SIZE))
        .into_iter()
        .filter(|s| [Technique::Forward, Technique::DeferredCompute].contains(&s.technique))
        .collect();
    // Linear 0.5 stored as sRGB 188, shown through gamma 1/2.2: 187.
    let blend = [187, 187, 0];
    for out in common::render_each(&scene, &settings) {
        let (x0, y0) = pixel_of(&scene, (SIZE, SIZE), 0.0, (-0.7, -0.7));
        let (x1, y1) = pixel_of(&scene, (SIZE, SIZE), 0.0, (0.7, 0.7));
        assert!(x1 > x0 + 6 && y1 > y0 + 6, "the quad covers ({x0}, {y0})–({x1}, {y1})");
        for y in y0..=y1 {
            for x in x0..=x1 {
                assert_close(&out, (x, y), blend, 3, "minified checker");
            }
        }
    }
}

/// A dark base-colour texture (sRGB 0–63, the darks of real models) seen at +5 EV, as auto
/// exposure shows a model lit by fitted lights: every technique gives forward's image within
/// the deferred tolerance (2/255). The G-buffer keeps the albedo sRGB-encoded, with the steps
/// the texture itself has; stored linear in 8 bits, these texels moved the image by up to
/// 7/255 (a public helmet model: 4,395 of 102,400 pixels beyond 1/255).
#[test]
fn dark_textures_keep_their_steps_through_the_gbuffer() {
    let mut w = GltfWriter::new();
    let texels: Vec<u8> = (0..32 * 32u32)
        .flat_map(|i| {
            let v = ((i * 7) % 64) as u8;
            [v, (v / 2) + 8, 63 - v, 255]
        })
        .collect();
    let texture = w.texture(png(32, 32, &texels), "image/png");
    let material = w.textured_material(Some(texture), None);
    let mut scene = row_of_quads(&mut w, &[(material, 0.0)], 1.2, 1.0);
    scene.lights = vec![ml_cpu::gpu_types::PointLight { position_radius: [0.3, -0.2, 1.5, 6.0], color: [1.0, 1.0, 1.0, 0.0] }];
    let settings: Vec<RenderSettings> = every_technique(ShadingModel::Pbr, DebugView::NONE, (SIZE, SIZE))
        .into_iter()
        .map(|s| RenderSettings { exposure: ml_render::Exposure::Ev(5.0), ..s })
        .collect();
    let out = common::render_each(&scene, &settings);
    let lit = out[0].rgba.chunks_exact(4).filter(|p| p[0].max(p[1]).max(p[2]) > 40).count();
    assert!(lit > SIZE as usize * SIZE as usize / 4, "the quad is hardly lit: {lit} pixels");
    for (s, o) in settings.iter().zip(&out).skip(1) {
        let (worst, pixels) = common::max_difference(&out[0], o);
        println!("{}: {pixels} pixels differ from forward, by up to {worst}/255", s.technique.name());
        assert!(worst <= 2, "{}: differs from forward by {worst}/255 on dark texels", s.technique.name());
    }
}

/// One image under eight samplers (eight textures of one image, as real files share an image
/// between textures): decoded and held once on the CPU (the textures share its texels) and
/// uploaded once — the renderer's memory as with one texture, within 1.2× (each copy of this
/// 1024² image and its mips would add 5.3 MiB).
#[test]
fn an_image_under_eight_samplers_is_held_and_uploaded_once() {
    let texels: Vec<u8> = (0..1024 * 1024u32).flat_map(|i| [(i % 251) as u8, (i % 241) as u8, (i % 239) as u8, 255]).collect();
    let image = png(1024, 1024, &texels);
    let scene = |samplers: bool| {
        let mut w = GltfWriter::new();
        let first = w.texture(image.clone(), "image/png");
        let wraps = [33071, 33648, 10497];
        let quads: Vec<(usize, f32)> = (0..8)
            .map(|k| {
                let texture = if samplers && k > 0 {
                    let t = w.json["textures"].as_array().unwrap().len();
                    w.json["textures"].as_array_mut().unwrap().push(json!({ "source": 0 }));
                    t
                } else {
                    first
                };
                if samplers {
                    w.sampler(texture, json!({ "wrapS": wraps[k % 3], "wrapT": wraps[k / 3] }));
                }
                (w.textured_material(Some(texture), None), k as f32 * 2.2 - 7.7)
            })
            .collect();
        row_of_quads(&mut w, &quads, 1.2, 8.0)
    };
    let (shared, single) = (scene(true), scene(false));
    assert_eq!((shared.textures.len(), single.textures.len()), (8, 1));
    assert!(shared.textures.iter().all(|t| std::sync::Arc::ptr_eq(&t.rgba, &shared.textures[0].rgba)), "the textures hold copies");
    let settings = [RenderSettings { shading: ShadingModel::Pbr, ..RenderSettings::new(Technique::Forward, 128, 16) }];
    let bytes = |s: &Scene| common::render_each(s, &settings)[0].stats.memory.expect("memory use").allocated;
    let (eight, one) = (bytes(&shared), bytes(&single));
    println!("8 samplers: {:.1} MiB; 1: {:.1} MiB", eight as f64 / 1048576.0, one as f64 / 1048576.0);
    assert!(eight as f64 <= one as f64 * 1.2, "8 samplers take {eight} bytes, one {one}");
}
