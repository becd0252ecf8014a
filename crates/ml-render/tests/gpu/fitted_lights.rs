//! Lights fitted to the scene (docs/scenes.md#lights-fitted-to-the-scene): every built-in
//! object kind, written as a glTF file at 0.01, 1 and 100 times its size, lit by 256 lights
//! of each layout and by the default rig (the file has no lights), renders neither black nor
//! blown out — the mean luma of the pixels it covers stays inside one band — and the same at
//! every size (the fitted frame and radius scale with the model, and the radiance falloff
//! depends on distance over radius only).

use crate::common;

use ml_cpu::environment::{EnvironmentAsk, EnvironmentSource};
use ml_cpu::gltf_writer::{mesh_primitive, GltfWriter};
use ml_cpu::lights::{LightLayout, RadiusRange};
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene_request::{SceneRequest, SceneSource};
use ml_render::{RenderOutput, RenderSettings, Renderer, Technique};
use serde_json::json;
use std::path::{Path, PathBuf};

/// The band of mean luma (Rec. 709 weights on the 8-bit, gamma-encoded values, 0…1) over the
/// covered pixels. Below: the model in pbr's ambient light alone gives 0.110 (checked: it
/// must stay under the band, or the band would not tell lit from unlit); above: over 0.7 the
/// lit parts are mostly white (the earlier fixed-box lights gave a big model ~0.95). Seen on
/// lavapipe: 0.130 (sphere, random) to 0.226 (cube, grid).
const BAND: (f32, f32) = (0.125, 0.7);
/// How far the luma of the same kind and layout may move between sizes.
const SCALE_TOLERANCE: f32 = 0.02;

/// `kind` in a grey dielectric material, scaled by `scale`, as a glTF file without lights or
/// camera.
fn write_kind(dir: &Path, kind: MeshKind, scale: f32) -> PathBuf {
    let mut w = GltfWriter::new();
    let material = w.material([0.8, 0.8, 0.8, 1.0], 0.0, 0.5);
    let index = w.mesh(&[mesh_primitive(&kind.build(), Some(material))]);
    w.node(json!({ "mesh": index, "scale": [scale, scale, scale] }), true);
    let path = dir.join(format!("{}-{scale}.glb", kind.name()));
    std::fs::write(&path, w.to_glb()).expect("the glTF file is written");
    path
}

/// (mean luma of the pixels not of the background colour, their share of the image).
fn covered_luma(out: &RenderOutput) -> (f32, f32) {
    let background = [5u8, 5, 5];
    let (mut sum, mut covered) = (0.0f32, 0usize);
    for p in out.rgba.chunks_exact(4) {
        if p[..3] != background {
            sum += (0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32) / 255.0;
            covered += 1;
        }
    }
    (sum / covered.max(1) as f32, covered as f32 / (out.width * out.height) as f32)
}

#[test]
fn every_kind_at_every_size_is_lit_inside_one_band() {
    let dir = std::env::temp_dir().join(format!("ml-fitted-lights-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ctx = common::pooled_context();
    // None: the default rig of a file without lights.
    let layouts = [None, Some(LightLayout::Grid), Some(LightLayout::Random), Some(LightLayout::Surface)];
    let mut outside = Vec::new();
    // The point lights alone: without the built-in sky a pbr file without lights gets.
    let render = |request: SceneRequest| {
        let built = request.asking(no_sky()).build().expect("the file builds");
        let settings = RenderSettings { shading: built.shading, ..RenderSettings::new(Technique::Forward, 96, 64) };
        let lights = built.scene.lights.len();
        (Renderer::new(&ctx, built.scene, settings).and_then(|mut r| r.render()).expect("render"), lights)
    };
    for kind in MeshKind::ALL {
        let mut at_unit_size = Vec::new();
        for scale in [1.0f32, 0.01, 100.0] {
            let path = write_kind(&dir, kind, scale);
            if scale == 1.0 {
                // Ambient light alone: one light too small to reach anything.
                let radius = Some(RadiusRange::fixed(1e-6));
                let dark = SceneRequest { lights: Some(1), radius, ..SceneRequest::new(SceneSource::File(path.clone())) };
                let (luma, _) = covered_luma(&render(dark).0);
                println!("{:>9} in ambient light alone: mean luma {luma:.3}", kind.name());
                if luma >= BAND.0 {
                    outside.push(format!("{} unlit: luma {luma:.3} is inside the band", kind.name()));
                }
            }
            for (i, layout) in layouts.iter().enumerate() {
                let request = SceneRequest {
                    lights: layout.map(|_| 256),
                    layout: layout.unwrap_or(LightLayout::Grid),
                    ..SceneRequest::new(SceneSource::File(path.clone()))
                };
                let (out, lights) = render(request);
                assert_eq!(lights, if layout.is_some() { 256 } else { 64 });
                let (luma, share) = covered_luma(&out);
                let name = layout.map_or("default rig", |l| l.name());
                println!("{:>9} × {scale:<5} {name:>11}: mean luma {luma:.3} over {:.0} % of the image", kind.name(), share * 100.0);
                if !(BAND.0..=BAND.1).contains(&luma) || share < 0.02 {
                    outside.push(format!("{} × {scale} {name}: luma {luma:.3}, {:.0} % covered", kind.name(), share * 100.0));
                }
                if scale == 1.0 {
                    at_unit_size.push(luma);
                } else if (luma - at_unit_size[i]).abs() > SCALE_TOLERANCE {
                    outside.push(format!("{} × {scale} {name}: luma {luma:.3} where size 1 gave {:.3}", kind.name(), at_unit_size[i]));
                }
            }
        }
    }
    drop(ctx);
    assert!(outside.is_empty(), "outside the band {BAND:?} or changed with the size:\n{}", outside.join("\n"));
}

/// The bounding box of the pixels not of the background colour: (x0, x1, y0, y1), inclusive.
fn covered_box(out: &RenderOutput) -> Option<(u32, u32, u32, u32)> {
    let mut b: Option<(u32, u32, u32, u32)> = None;
    for (i, p) in out.rgba.chunks_exact(4).enumerate() {
        if p[..3] != [5u8, 5, 5] {
            let (x, y) = (i as u32 % out.width, i as u32 / out.width);
            b = Some(b.map_or((x, x, y, y), |(x0, x1, y0, y1)| (x0.min(x), x1.max(x), y0.min(y), y1.max(y))));
        }
    }
    b
}

/// A file without a camera is framed for the image it is rendered to: every built-in object
/// kind, written as a glTF file at 0.01, 1 and 100 times its size and rendered at 16:9 and
/// 9:16, covers at least 70 % of the image's width or height (whichever the model fills
/// first), and none of it is cut by the image's border.
#[test]
fn a_file_without_a_camera_is_framed_to_fill_the_image() {
    let dir = std::env::temp_dir().join(format!("ml-framing-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ctx = common::pooled_context();
    let mut failures = Vec::new();
    let mut least = f32::MAX;
    for kind in MeshKind::ALL {
        for scale in [1.0f32, 0.01, 100.0] {
            let path = write_kind(&dir, kind, scale);
            for (width, height) in [(160u32, 90u32), (90, 160)] {
                // Framing alone: without the sky (prefiltered anew for each of the 42 renders).
                let aspect = width as f32 / height as f32;
                let request = SceneRequest { aspect, ..SceneRequest::new(SceneSource::File(path.clone())) }.asking(no_sky());
                let built = request.build().expect("the file builds");
                let settings = RenderSettings { shading: built.shading, ..RenderSettings::new(Technique::Forward, width, height) };
                let out = Renderer::new(&ctx, built.scene, settings).and_then(|mut r| r.render()).expect("render");
                let Some((x0, x1, y0, y1)) = covered_box(&out) else {
                    failures.push(format!("{} × {scale} at {width}x{height}: nothing covered", kind.name()));
                    continue;
                };
                let (w, h) = ((x1 - x0 + 1) as f32 / width as f32, (y1 - y0 + 1) as f32 / height as f32);
                println!(
                    "{:>9} × {scale:<5} {width}x{height}: covers {:.0} % of the width, {:.0} % of the height",
                    kind.name(),
                    w * 100.0,
                    h * 100.0
                );
                least = least.min(w.max(h));
                if w.max(h) < 0.7 {
                    failures.push(format!("{} × {scale} at {width}x{height}: {:.0} % × {:.0} %", kind.name(), w * 100.0, h * 100.0));
                }
                if x0 == 0 || y0 == 0 || x1 == width - 1 || y1 == height - 1 {
                    failures.push(format!("{} × {scale} at {width}x{height}: cut by the border ({x0}..{x1}, {y0}..{y1})", kind.name()));
                }
            }
        }
    }
    println!("the least binding share: {:.0} %", least * 100.0);
    drop(ctx);
    assert!(failures.is_empty(), "badly framed:\n{}", failures.join("\n"));
}

/// `--show-lights` on the seed scene's 64-light grid, in every technique: at the pixel where
/// each light's rest place projects (where its marker's centre is), the colour is the light's
/// — the channels it has are bright, the ones it lacks dark — and without markers it is not.
#[test]
fn shown_lights_are_blobs_of_their_colour_in_every_technique() {
    use ml_cpu::material::Material;
    let source = SceneSource::Seed { object: MeshKind::Sphere, material: Material::named("gold").unwrap() };
    // From further back and higher than the seed's camera, which sees few of the lights.
    let camera = Some(ml_cpu::camera::CameraSpec::parse("0,30,42:0,2,0:60").unwrap());
    let plain = SceneRequest { camera, ..SceneRequest::new(source.clone()) }.build().unwrap().scene;
    let shown = SceneRequest { show_lights: true, camera, ..SceneRequest::new(source) }.build().unwrap().scene;
    let (width, height) = (256u32, 144u32);
    let techniques = Technique::ALL.to_vec();
    let settings: Vec<RenderSettings> = techniques.iter().map(|&t| RenderSettings::new(t, width, height)).collect();
    let with = common::render_each(&shown, &settings);
    let without = common::render(plain.clone(), settings[0]);
    let view_proj = plain.camera.projection(width as f32 / height as f32) * plain.camera.view();
    let mut seen = 0;
    for light in &plain.lights {
        let ndc = view_proj.project_point3(glam::Vec3::from_slice(&light.position_radius[..3]));
        if ndc.x.abs() > 0.95 || ndc.y.abs() > 0.95 || !(0.0..1.0).contains(&ndc.z) {
            continue;
        }
        seen += 1;
        let (x, y) = (((ndc.x + 1.0) * 0.5 * width as f32) as u32, ((ndc.y + 1.0) * 0.5 * height as f32) as u32);
        let has = light.color.map(|c| c > 0.0);
        for (out, technique) in with.iter().zip(&techniques) {
            let p = common::pixel(out, x, y);
            let matches = (0..3).all(|c| if has[c] { p[c] >= 200 } else { p[c] <= 60 });
            assert!(matches, "{technique:?}: light at {:?} (colour {:?}) shows {p:?} at ({x}, {y})", light.position_radius, light.color);
        }
        let bare = common::pixel(&without, x, y);
        assert!(!(0..3).all(|c| if has[c] { bare[c] >= 200 } else { bare[c] <= 60 }), "without markers: {bare:?} at ({x}, {y})");
    }
    println!("{seen} of 64 lights in view, each a blob of its colour in {} techniques", techniques.len());
    assert_eq!(seen, 64, "lights out of view");
}

/// No environment: the point lights alone, where a pbr file without lights gets the sky.
fn no_sky() -> EnvironmentAsk {
    EnvironmentAsk { source: Some(EnvironmentSource::Off), ..Default::default() }
}
