//! glTF's PBR extensions' textures: the clear coat's strength, roughness and normal, the
//! sheen's colour and roughness, the specular strength and colour, transmission and the
//! volume's thickness. Each multiplies its factor at every point: a quad textured with one
//! texel renders as the quad whose factor is multiplied by that texel, in every technique
//! (the deferred ones carry the texels through the G-buffer, the transparent layers in their
//! nodes), and differs from the quad whose texture is ignored (the clear coat's normal map,
//! which no factor stands for, by the techniques' agreement).

use crate::common;

use glam::Quat;
use ml_cpu::environment::{Environment, EnvironmentImage};
use ml_cpu::gltf_writer::{png, quad, GltfWriter, PrimitiveData};
use ml_cpu::gpu_types::PointLight;
use ml_cpu::scene::Scene;
use ml_render::{Antialiasing, RenderSettings, ShadingModel, Technique};
use serde_json::{json, Value};
use std::sync::Arc;

const WIDTH: u32 = 216;
const HEIGHT: u32 = 48;

/// One quad's extension: its name, its object (factors; the texture's field), the texel the
/// texture holds (RGBA), the same factors multiplied by that texel (None: no factor says
/// what the texture does — the clear coat's normal), and whether the texel is a colour (sRGB).
struct Case {
    extension: &'static str,
    factors: Value,
    field: &'static str,
    texel: [u8; 4],
    multiplied: Option<Value>,
}

fn srgb(c: u8) -> f64 {
    let c = c as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn unorm(c: u8) -> f64 {
    c as f64 / 255.0
}

fn cases() -> Vec<Case> {
    let (sheen, specular) = ([200, 60, 120, 255], [255, 80, 40, 255]);
    vec![
        Case {
            extension: "KHR_materials_clearcoat",
            factors: json!({ "clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.1 }),
            field: "clearcoatTexture",
            texel: [102, 0, 0, 255],
            multiplied: Some(json!({ "clearcoatFactor": unorm(102), "clearcoatRoughnessFactor": 0.1 })),
        },
        Case {
            extension: "KHR_materials_clearcoat",
            factors: json!({ "clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.8 }),
            field: "clearcoatRoughnessTexture",
            texel: [0, 64, 0, 255],
            multiplied: Some(json!({ "clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.8 * unorm(64) })),
        },
        Case {
            extension: "KHR_materials_clearcoat",
            factors: json!({ "clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.15 }),
            field: "clearcoatNormalTexture",
            texel: [200, 150, 220, 255],
            multiplied: None,
        },
        Case {
            extension: "KHR_materials_sheen",
            factors: json!({ "sheenColorFactor": [1.0, 1.0, 1.0], "sheenRoughnessFactor": 0.5 }),
            field: "sheenColorTexture",
            texel: sheen,
            multiplied: Some(json!({ "sheenColorFactor": [srgb(sheen[0]), srgb(sheen[1]), srgb(sheen[2])], "sheenRoughnessFactor": 0.5 })),
        },
        Case {
            extension: "KHR_materials_sheen",
            factors: json!({ "sheenColorFactor": [0.8, 0.8, 0.8], "sheenRoughnessFactor": 0.9 }),
            field: "sheenRoughnessTexture",
            texel: [0, 0, 0, 51],
            multiplied: Some(json!({ "sheenColorFactor": [0.8, 0.8, 0.8], "sheenRoughnessFactor": 0.9 * unorm(51) })),
        },
        Case {
            extension: "KHR_materials_specular",
            factors: json!({ "specularFactor": 1.0 }),
            field: "specularTexture",
            texel: [0, 0, 0, 25],
            multiplied: Some(json!({ "specularFactor": unorm(25) })),
        },
        Case {
            extension: "KHR_materials_specular",
            factors: json!({ "specularColorFactor": [2.0, 2.0, 2.0] }),
            field: "specularColorTexture",
            texel: specular,
            multiplied: Some(json!({ "specularColorFactor": [2.0 * srgb(specular[0]), 2.0 * srgb(specular[1]), 2.0 * srgb(specular[2])] })),
        },
        Case {
            extension: "KHR_materials_transmission",
            factors: json!({ "transmissionFactor": 1.0 }),
            field: "transmissionTexture",
            texel: [77, 0, 0, 255],
            multiplied: Some(json!({ "transmissionFactor": unorm(77) })),
        },
        Case {
            extension: "KHR_materials_volume",
            factors: json!({ "thicknessFactor": 1.0, "attenuationDistance": 0.4, "attenuationColor": [1.0, 0.3, 0.1] }),
            field: "thicknessTexture",
            texel: [0, 26, 0, 255],
            multiplied: Some(json!({ "thicknessFactor": unorm(26), "attenuationDistance": 0.4, "attenuationColor": [1.0, 0.3, 0.1] })),
        },
    ]
}

/// How each quad's extension is given.
#[derive(Clone, Copy, PartialEq)]
enum Variant {
    /// Factors and the texture.
    Textured,
    /// The factors times the texel, no texture (the clear coat's normal keeps its texture).
    Multiplied,
    /// Factors alone: the texture ignored.
    Ignored,
}

/// The quads in a row before an unlit white wall, lit by point lights and the sky, each with
/// one case's extension as `variant` gives it (a transmitting quad transmits through the
/// volume case's too).
fn scene(variant: Variant) -> Scene {
    let mut w = GltfWriter::new();
    let cases = cases();
    let facing = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let count = cases.len() as f32;
    for (i, case) in cases.iter().enumerate() {
        let transmits = case.extension == "KHR_materials_transmission" || case.extension == "KHR_materials_volume";
        let m = if transmits { w.material([0.9, 0.9, 0.9, 1.0], 0.0, 0.2) } else { w.material([0.7, 0.3, 0.2, 1.0], 0.0, 0.5) };
        let mut body = case.factors.clone();
        match (variant, &case.multiplied) {
            (Variant::Multiplied, Some(multiplied)) => body = multiplied.clone(),
            (Variant::Ignored, _) => {}
            _ => {
                let texture = w.texture(png(1, 1, &case.texel), "image/png");
                body[case.field] = json!({ "index": texture });
            }
        }
        let mut extensions = json!({ case.extension: body });
        if case.extension == "KHR_materials_volume" {
            extensions["KHR_materials_transmission"] = json!({ "transmissionFactor": 1.0 });
        }
        w.json["materials"][m]["extensions"] = extensions;
        let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
        let x = (i as f32 - (count - 1.0) / 2.0) * 2.2;
        w.node(json!({ "mesh": mesh, "translation": [x, 0.0, 0.0], "rotation": facing.to_array(), "scale": [0.9, 1.0, 0.9] }), true);
    }
    let wall = w.material([1.0, 1.0, 1.0, 1.0], 0.0, 1.0);
    w.json["materials"][wall]["extensions"] = json!({ "KHR_materials_unlit": {} });
    let mesh = w.mesh(&[PrimitiveData { material: Some(wall), ..quad() }]);
    w.node(json!({ "mesh": mesh, "translation": [0.0, 0.0, -1.0], "rotation": facing.to_array(), "scale": [count * 1.2, 1.0, 0.5] }), true);
    let half_height = 1.1;
    let ortho = json!({ "xmag": half_height * WIDTH as f32 / HEIGHT as f32, "ymag": half_height, "znear": 0.1, "zfar": 50.0 });
    let camera = w.camera(json!({ "type": "orthographic", "orthographic": ortho }));
    w.node(json!({ "camera": camera, "translation": [0.0, 0.0, 10.0] }), true);
    w.json["extensionsUsed"] =
        json!(cases.iter().map(|c| c.extension).chain(["KHR_materials_unlit", "KHR_materials_transmission"]).collect::<Vec<_>>());
    let (mut scene, warnings) = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
    assert!(warnings.is_empty(), "{warnings:?}");
    let light = |x: f32, color: [f32; 3]| PointLight { position_radius: [x, 1.2, 2.0, 9.0], color: [color[0], color[1], color[2], 0.0] };
    scene.lights = vec![light(-6.0, [3.0, 2.0, 1.5]), light(0.0, [1.5, 2.5, 3.0]), light(6.0, [2.5, 2.5, 2.0])];
    scene.sections.set(Some(Environment { image: Arc::new(EnvironmentImage::sky(64)), intensity: 0.6, rotation: 0.0, background: false }));
    scene
}

fn pbr(technique: Technique) -> RenderSettings {
    RenderSettings { shading: ShadingModel::Pbr, ..RenderSettings::new(technique, WIDTH, HEIGHT) }
}

/// Pixels of quad `i`'s column that differ by more than 3/255 between `a` and `b`.
fn changed_in_column(a: &ml_render::RenderOutput, b: &ml_render::RenderOutput, i: usize, columns: usize) -> usize {
    let (x0, x1) = (i as u32 * WIDTH / columns as u32, (i as u32 + 1) * WIDTH / columns as u32);
    (x0..x1)
        .flat_map(|x| (0..HEIGHT).map(move |y| (x, y)))
        .filter(|&(x, y)| common::pixel(a, x, y).iter().zip(common::pixel(b, x, y)).any(|(p, q)| p.abs_diff(q) > 3))
        .count()
}

#[test]
fn each_extension_texture_multiplies_its_factor_in_every_technique() {
    let (textured, multiplied, ignored) = (scene(Variant::Textured), scene(Variant::Multiplied), scene(Variant::Ignored));
    let cases = cases();
    // Every technique, and with 4 samples a pixel (the multisampled G-buffer's and the sample
    // buffer's paths) those that have their own.
    let mut settings: Vec<RenderSettings> = Technique::ALL.into_iter().map(pbr).collect();
    for technique in [Technique::Forward, Technique::Deferred, Technique::DeferredCompute, Technique::Visibility] {
        settings.push(RenderSettings { antialiasing: Antialiasing::X4, ..pbr(technique) });
    }
    let mut textured_forward: Option<ml_render::RenderOutput> = None;
    for s in &settings {
        let what = format!("{} {:?}", s.technique.name(), s.antialiasing);
        let with_texture = common::render_each(&textured, std::slice::from_ref(s)).remove(0);
        let with_product = common::render_each(&multiplied, std::slice::from_ref(s)).remove(0);
        let (worst, differing) = common::max_difference(&with_texture, &with_product);
        println!("{what}: textured against multiplied factors: {differing} pixels differ, by up to {worst}/255");
        assert!(worst <= 1, "{what}: the textured quads differ from the multiplied factors by {worst}/255");
        // The techniques agree on the textured quads (the clear coat's normal map included).
        if let Some(forward) = textured_forward.as_ref().filter(|_| s.antialiasing == Antialiasing::Off) {
            let (worst, differing) = common::max_difference(forward, &with_texture);
            println!("{what}: textured against forward: {differing} pixels differ, by up to {worst}/255");
            assert!(worst <= 2, "{what}: differs from forward by {worst}/255");
        }
        if textured_forward.is_none() {
            // Each texture matters: ignored, its quad changes (once, in forward: a technique
            // that ignored one would already differ from the multiplied factors above).
            let without = common::render_each(&ignored, std::slice::from_ref(s)).remove(0);
            for (i, case) in cases.iter().enumerate() {
                let changed = changed_in_column(&with_texture, &without, i, cases.len());
                println!("{what} {}: {changed} pixels change without the texture", case.field);
                assert!(changed > 100, "{what}: ignoring the {} changes only {changed} pixels", case.field);
            }
            textured_forward = Some(with_texture);
        }
    }
}
