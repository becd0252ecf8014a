//! The command line: a good render prints its table and writes its PNG; bad input gets one
//! clear error line and a non-zero exit, never a panic.

use crate::common;

use common::assert_one_line_error;
use std::path::PathBuf;
use std::process::{Command, Output};

fn manylights(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_manylights"));
    cmd.args(args);
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("run manylights")
}

fn temp_png(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("manylights-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn renders_a_png_and_prints_the_table() {
    let png = temp_png("ok.png");
    let out =
        manylights(&["render", "--validation", "--width", "64", "--height", "36", "--time", "0", "--out", png.to_str().unwrap()], &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    for key in ["device", "resolution", "64x36", "lights", "gpu ms", "memory", "MiB in", "cpu ms/frame"] {
        assert!(stdout.contains(key), "'{key}' missing from:\n{stdout}");
    }
    let img = image::open(&png).expect("a PNG").to_rgba8();
    assert_eq!(img.dimensions(), (64, 36));
}

/// Warm-up frames are rendered and thrown away: the image is the one without them, and the
/// table's frames are the measured ones.
#[test]
fn a_warm_up_changes_no_pixel() {
    let (cold, warm) = (temp_png("cold.png"), temp_png("warm.png"));
    for (png, warmup) in [(&cold, "0"), (&warm, "3")] {
        let args = ["render", "--validation", "--scene", "bench", "--lights", "2000", "--technique", "deferred-compute", "--width", "64"];
        let out = manylights(
            &[&args[..], &["--height", "36", "--frames", "2", "--warmup", warmup, "--out", png.to_str().unwrap()]].concat(),
            &[],
        );
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
        assert!(stdout.lines().any(|l| l.split_whitespace().collect::<Vec<_>>() == ["frames", "2"]), "{stdout}");
    }
    assert_eq!(std::fs::read(&cold).unwrap(), std::fs::read(&warm).unwrap(), "the warm-up changed the image");
}

/// `MANYLIGHTS_PIPELINE_STATS` never changes what a run does: on a device that reports
/// pipeline statistics, one line per compute pipeline (the lighting's among them); on one that
/// does not (lavapipe), one line that says so. The image is rendered either way.
#[test]
fn pipeline_stats_are_printed_or_declined_in_one_line() {
    let png = temp_png("stats.png");
    let args = ["render", "--validation", "--scene", "bench", "--technique", "deferred-compute", "--width", "32", "--height", "18"];
    let out = manylights(&[&args[..], &["--frames", "1", "--out", png.to_str().unwrap()]].concat(), &[("MANYLIGHTS_PIPELINE_STATS", "1")]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{}{stderr}", String::from_utf8_lossy(&out.stdout));
    let declined: Vec<&str> = stderr.lines().filter(|l| l.contains("does not report pipeline statistics")).collect();
    let printed: Vec<&str> = stderr.lines().filter(|l| l.starts_with("pipeline stats: ")).collect();
    if declined.is_empty() {
        assert!(printed.iter().any(|l| l.contains("shading/deferred_lighting.comp")), "{stderr}");
    } else {
        assert_eq!((declined.len(), printed.len()), (1, 0), "{stderr}");
        assert!(declined[0].starts_with("MANYLIGHTS_PIPELINE_STATS: "), "{stderr}");
    }
    assert!(std::fs::metadata(&png).unwrap().len() > 0);
}

#[test]
fn clustered_render_reports_its_clusters() {
    let png = temp_png("clustered.png");
    let out = manylights(
        &[
            "render",
            "--validation",
            "--technique",
            "clustered-cpu",
            "--clusters",
            "4x4x2",
            "--width",
            "64",
            "--height",
            "36",
            "--out",
            png.to_str().unwrap(),
        ],
        &[],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    for key in ["clustered-cpu", "cpu assign ms", "4x4x2 = 32", "lights/cluster", "index list"] {
        assert!(stdout.contains(key), "'{key}' missing from:\n{stdout}");
    }
}

#[test]
fn info_lists_a_device() {
    let out = manylights(&["info"], &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(stdout.contains("device") && stdout.contains("maxStorageBufferRange"), "{stdout}");
}

#[test]
fn bad_names_are_refused_with_the_choices() {
    let png = temp_png("never.png");
    let p = png.to_str().unwrap();
    assert_one_line_error(&manylights(&["render", "--technique", "raytraced", "--out", p], &[]), &["raytraced", "forward"]);
    assert_one_line_error(&manylights(&["render", "--object", "venus", "--out", p], &[]), &["venus", "teapot"]);
    assert_one_line_error(&manylights(&["render", "--material", "mithril", "--out", p], &[]), &["mithril", "gold"]);
    assert_one_line_error(&manylights(&["render", "--light-layout", "spiral", "--out", p], &[]), &["spiral", "grid"]);
    assert_one_line_error(&manylights(&["render", "--light-radius", "3..1", "--out", p], &[]), &["3..1"]);
    assert_one_line_error(&manylights(&["render", "--scene", "nope", "--out", p], &[]), &["nope"]);
    assert_one_line_error(&manylights(&["render", "--width", "wide", "--out", p], &[]), &["wide"]);
    assert_one_line_error(&manylights(&["render", "--clusters", "16x9", "--out", p], &[]), &["--clusters 16x9"]);
    assert_one_line_error(&manylights(&["render", "--clusters", "0x9x24", "--out", p], &[]), &["--clusters 0x9x24"]);
    assert_one_line_error(&manylights(&["render", "--debug-view", "xray", "--out", p], &[]), &["xray", "cluster-heat"]);
    assert_one_line_error(&manylights(&["render", "--debug-view", "cluster-heat", "--out", p], &[]), &["clustered forward technique"]);
    assert_one_line_error(
        &manylights(&["render", "--technique", "deferred-compute", "--debug-view", "cluster-heat", "--out", p], &[]),
        &["clustered forward technique"],
    );
    assert_one_line_error(&manylights(&["render", "--shading", "phong", "--out", p], &[]), &["phong", "blinn-phong", "pbr"]);
    assert_one_line_error(&manylights(&["render", "--debug-view", "shadow-map", "--out", p], &[]), &["shadow-map", "blinn-phong"]);
    assert_one_line_error(&manylights(&["render", "--omni-shadow", "sideways", "--out", p], &[]), &["sideways", "layered"]);
    assert_one_line_error(&manylights(&["render", "--debug-view", "shadow-cube", "--out", p], &[]), &["shadow-cube", "--omni-shadow"]);
    assert_one_line_error(&manylights(&["render", "--shadowed-lights", "4", "--out", p], &[]), &["--shadowed-lights", "--omni-shadow"]);
    assert_one_line_error(&manylights(&["render", "--sun-shadow", "raytraced", "--out", p], &[]), &["raytraced", "graphics", "compute"]);
    assert!(!png.exists());
}

#[test]
fn deferred_render_reports_its_gbuffer_and_passes() {
    let png = temp_png("deferred.png");
    let args =
        ["render", "--validation", "--technique", "deferred-clustered", "--shading", "blinn-phong", "--width", "64", "--height", "36"];
    let out = manylights(&[&args[..], &["--out", png.to_str().unwrap()]].concat(), &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    for key in ["blinn-phong", "g-buffer + lighting pass", "tone map pass", "16 bytes/pixel", "transient", "shadow map by graphics"] {
        assert!(stdout.contains(key), "'{key}' missing from:\n{stdout}");
    }
}

#[test]
fn absurd_sizes_and_counts_are_refused() {
    // One technique, named: `auto` measures the device, and under load may pick another
    // technique whose checks come in another order.
    let render = |args: &[&str]| {
        let mut all = vec!["render", "--technique", "forward"];
        all.extend_from_slice(args);
        manylights(&all, &[])
    };
    let png = temp_png("never2.png");
    let p = png.to_str().unwrap();
    assert_one_line_error(&render(&["--lights", "0", "--out", p]), &["--lights 0"]);
    assert_one_line_error(&render(&["--lights", "100000000", "--out", p]), &["--lights 100000000", "67108864"]);
    assert_one_line_error(&render(&["--width", "0", "--out", p]), &["--width 0"]);
    assert_one_line_error(&render(&["--height", "100000", "--out", p]), &["--height 100000"]);
    assert_one_line_error(&render(&["--frames", "0", "--out", p]), &["--frames"]);
    let bench = |n: &str| render(&["--scene", "bench", "--objects", n, "--out", p]);
    assert_one_line_error(&bench("100001"), &["--objects 100001", "100000"]);
    assert_one_line_error(&render(&["--objects", "10", "--out", p]), &["--objects", "--scene bench"]);
    let omni = |k: &str, size: &str| render(&["--omni-shadow", "direct", "--shadowed-lights", k, "--cube-size", size, "--out", p]);
    assert_one_line_error(&omni("65", "64"), &["--shadowed-lights 65", "64 lights"]);
    assert_one_line_error(&omni("0", "64"), &["--shadowed-lights 0"]);
    assert_one_line_error(&omni("1", "0"), &["--cube-size 0"]);
    assert_one_line_error(&omni("64", "8192"), &["shadow cubes", "MiB"]);
    // The compute raster's depths are one storage buffer: 2 × 6 × 2048² × 4 bytes = 192 MiB,
    // past lavapipe's 128 MiB.
    let compute = render(&["--omni-shadow", "compute", "--shadowed-lights", "2", "--cube-size", "2048", "--out", p]);
    assert_one_line_error(&compute, &["--omni-shadow compute", "192 MiB", "storage buffer"]);
    // The shadow atlas: budgets of nothing or more than the device has, sizes that are no
    // face size, more lights than it takes, a budget too small for every face.
    let atlas = |extra: &[&str]| {
        let mut args = vec!["--omni-shadow", "atlas", "--width", "64", "--height", "64", "--out", p];
        args.extend_from_slice(extra);
        render(&args)
    };
    assert_one_line_error(&atlas(&["--shadow-budget", "0"]), &["shadow budget of 0 MiB", "out of range"]);
    assert_one_line_error(&atlas(&["--shadow-budget", "4000000"]), &["shadow budget of 4000000 MiB", "device memory"]);
    assert_one_line_error(&atlas(&["--cube-size", "100"]), &["--cube-size 100", "power of two"]);
    assert_one_line_error(&atlas(&["--scene", "bench", "--lights", "5000", "--shadowed-lights", "5000"]), &["4096", "5000"]);
    assert_one_line_error(&atlas(&["--shadowed-lights", "all", "--shadow-budget", "1"]), &["shadow atlas", "MiB"]);
    assert!(!png.exists());
}

#[test]
fn unwritable_output_is_refused_before_rendering() {
    let missing = std::env::temp_dir().join("manylights-no-such-folder/a.png");
    assert_one_line_error(&manylights(&["render", "--out", missing.to_str().unwrap()], &[]), &["does not exist"]);
    let dir = temp_png("a-folder.png");
    std::fs::create_dir_all(&dir).unwrap();
    assert_one_line_error(&manylights(&["render", "--out", dir.to_str().unwrap()], &[]), &["directory"]);
}

/// Cluster lists that cannot fit in what the device binds are refused before any frame is
/// drawn — in seconds, not after minutes of list building — in one line that names the
/// technique asked for and the flags that fix it. (The light grid of the other techniques
/// lists each light once.)
#[test]
fn light_lists_that_cannot_fit_are_refused_before_any_frame() {
    let png = temp_png("never-lists.png");
    for technique in ["clustered-cpu", "deferred-clustered"] {
        let start = std::time::Instant::now();
        let args = [
            "render",
            "--validation",
            "--technique",
            technique,
            "--lights",
            "200000",
            "--light-radius",
            "500",
            "--width",
            "64",
            "--height",
            "36",
        ];
        let out = manylights(&[&args[..], &["--out", png.to_str().unwrap()]].concat(), &[]);
        let needles = [&format!("{technique}: the cluster light lists need at least")[..], "--light-radius", "--lights", "--clusters"];
        assert_one_line_error(&out, &needles);
        let seconds = start.elapsed().as_secs_f64();
        println!("{technique}: refused in {seconds:.1} s");
        assert!(seconds < 120.0, "{technique}: refused only after {seconds:.0} s");
        assert!(!png.exists());
    }
}

#[test]
fn no_vulkan_driver_names_what_to_install() {
    let png = temp_png("never3.png");
    let out = manylights(
        &["render", "--out", png.to_str().unwrap()],
        &[("VK_DRIVER_FILES", "/nonexistent"), ("VK_ICD_FILENAMES", "/nonexistent")],
    );
    assert_one_line_error(&out, &["no Vulkan driver", "mesa-vulkan-drivers"]);
    let out = manylights(&["info"], &[("VK_DRIVER_FILES", "/nonexistent"), ("VK_ICD_FILENAMES", "/nonexistent")]);
    assert_one_line_error(&out, &["no Vulkan driver"]);
}

#[test]
fn missing_device_index_is_refused() {
    let png = temp_png("never4.png");
    assert_one_line_error(&manylights(&["render", "--device", "99", "--out", png.to_str().unwrap()], &[]), &["--device 99"]);
}

/// Each broken text and a fragment of the error it must give.
fn broken_scene_files() -> Vec<(&'static str, &'static str)> {
    vec![
        ("", "missing field `objects`"),
        ("objects = []", "no objects"),
        ("[[objects]]\nmesh = \"sphere\"\n[[objects]\n", "line 3"),
        ("[[objects]]\nmesh = \"sphere\"\ncolour = 1\n", "unknown field `colour`"),
        ("[[objects]]\nmesh = \"cylinder\"\n", "unknown object 'cylinder'"),
        ("[[objects]]\n", "needs a mesh"),
        ("[[objects]]\nmesh = \"sphere\"\ngltf = \"a.gltf\"\n", "either mesh or gltf"),
        ("[[objects]]\nmesh = 3\n", "invalid type"),
        ("[[objects]]\nmesh = \"sphere\"\nposition = [1.0, 2.0]\n", "line 3"),
        ("[[objects]]\nmesh = \"sphere\"\nposition = [nan, 0.0, 0.0]\n", "not a finite number"),
        ("[[objects]]\nmesh = \"sphere\"\nposition = [inf, 0.0, 0.0]\n", "not a finite number"),
        ("[[objects]]\nmesh = \"sphere\"\nscale = 0.0\n", "scale 0 must be greater than 0"),
        ("[[objects]]\nmesh = \"sphere\"\nscale = -2.0\n", "scale -2 must be greater than 0"),
        ("[[objects]]\nmesh = \"sphere\"\nmaterial = { roughness = 1.5 }\n", "roughness 1.5 must lie in [0, 1]"),
        ("[[objects]]\nmesh = \"sphere\"\nmaterial = { metallic = -0.1 }\n", "metallic -0.1 must lie in [0, 1]"),
        ("[[objects]]\nmesh = \"sphere\"\nmaterial = { albedo = [-1.0, 0.0, 0.0] }\n", "albedo -1 must not be negative"),
        ("[[objects]]\nmesh = \"sphere\"\nmaterial = { name = \"mithril\" }\n", "unknown material 'mithril'"),
        ("[[objects]]\nmesh = \"sphere\"\n[[lights]]\ncolor = [1.0, 1.0, 1.0]\n", "a point or spot light needs a position"),
        ("[[objects]]\nmesh = \"sphere\"\n[[lights]]\nkind = \"directional\"\n", "a directional light needs a direction"),
        ("[[objects]]\nmesh = \"sphere\"\n[[lights]]\nkind = \"spot\"\nposition = [0.0, 1.0, 0.0]\n", "a spot light needs a direction"),
        ("[[objects]]\nmesh = \"sphere\"\n[[lights]]\nkind = \"spot\"\nposition = [0.0, 1.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\ninner_deg = 30.0\nouter_deg = 20.0\n", "need 0 ≤ inner < outer ≤ 90"),
        ("[[objects]]\nmesh = \"sphere\"\n[[lights]]\nkind = \"directional\"\ndirection = [0.0, 0.0, 0.0]\n", "must not be zero"),
        (
            "[[objects]]\nmesh = \"sphere\"\n[[lights]]\nkind = \"directional\"\ndirection = [0.0, -1.0, 0.0]\nradius = 3.0\n",
            "no position or radius",
        ),
        ("[[objects]]\nmesh = \"sphere\"\n[[lights]]\nposition = [0.0, 1.0, 0.0]\nradius = 0.0\n", "radius 0 must be greater than 0"),
        (
            "[[objects]]\nmesh = \"sphere\"\n[[lights]]\nposition = [0.0, 1.0, 0.0]\ncolor = [1.0, -1.0, 0.0]\n",
            "color -1 must not be negative",
        ),
        ("[[objects]]\nmesh = \"sphere\"\n[[lights]]\nkind = \"area\"\nposition = [0.0, 1.0, 0.0]\n", "unknown kind 'area'"),
        ("[[objects]]\nmesh = \"sphere\"\n[camera]\nfov_y_deg = 180.0\n", "fov_y_deg 180"),
        ("[[objects]]\nmesh = \"sphere\"\n[camera]\nnear = 10.0\nfar = 1.0\n", "near 10 must be less than far 1"),
        ("[[objects]]\nmesh = \"sphere\"\n[camera]\nposition = [1.0, 1.0, 1.0]\ntarget = [1.0, 1.0, 1.0]\n", "the same point"),
        ("[[objects]]\nmesh = \"sphere\"\n[camera]\nposition = [0.0, 5.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\n", "straight up or down"),
        ("[[objects]]\nmesh = \"sphere\"\n[shading]\nambient = -1.0\n", "ambient -1 must not be negative"),
        ("[[objects]]\nmesh = \"sphere\"\n[shading]\nmodel = 7\n", "invalid type"),
        ("[[objects]]\nmesh = \"sphere\"\n[camera]\nzoom = 2.0\n", "unknown field `zoom`"),
        ("objects = \"sphere\"", "invalid type"),
        ("[[objects]]\nmesh = \"sphere\"\nposition = [1e39, 0.0, 0.0]\n", "not a finite number"),
        ("[[objects]]\nmesh = \"sphere\"\n[camera]\northo_half_height = 0.0\n", "ortho_half_height 0 must be greater than 0"),
    ]
}

/// Every broken scene file (written by this test from the table above) ends the run with one
/// error line naming the file and the problem, exit code 1, no PNG.
#[test]
fn broken_scene_files_are_refused_one_line_each() {
    let png = temp_png("never-scene.png");
    let p = png.to_str().unwrap();
    for (i, (text, expected)) in broken_scene_files().into_iter().enumerate() {
        let file = temp_png(&format!("broken-{i}.toml"));
        std::fs::write(&file, text).unwrap();
        let out = manylights(&["render", "--scene", file.to_str().unwrap(), "--out", p], &[]);
        assert_one_line_error(&out, &[expected, file.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(1), "{text:?}");
    }
    assert!(!png.exists());
}

/// A valid glTF (a quad, a point light) as the writer makes it, for breaking.
fn good_gltf() -> ml_cpu::gltf_writer::GltfWriter {
    use serde_json::json;
    let mut w = ml_cpu::gltf_writer::GltfWriter::new();
    let mesh = w.mesh(&[ml_cpu::gltf_writer::quad()]);
    w.node(json!({ "mesh": mesh }), true);
    let light = w.light(json!({ "type": "point", "intensity": 4.0 }));
    w.node(json!({ "translation": [0.0, 2.0, 0.0], "extensions": { "KHR_lights_punctual": { "light": light } } }), true);
    w
}

/// `good_gltf` with a base-colour texture on its quad, broken by `f`.
fn textured(f: &dyn Fn(&mut ml_cpu::gltf_writer::GltfWriter)) -> Vec<u8> {
    let mut w = good_gltf();
    let t = w.texture(ml_cpu::gltf_writer::png(1, 1, &[255, 0, 0, 255]), "image/png");
    let m = w.textured_material(Some(t), None);
    w.json["meshes"][0]["primitives"][0]["material"] = serde_json::json!(m);
    f(&mut w);
    w.to_gltf()
}

/// Each broken glTF (bytes, file extension) and a fragment of the error it must give.
fn broken_gltf_files() -> Vec<(Vec<u8>, &'static str, &'static str)> {
    use serde_json::json;
    let good = good_gltf();
    let text = |w: &ml_cpu::gltf_writer::GltfWriter| w.to_gltf();
    let edit = |f: &dyn Fn(&mut ml_cpu::gltf_writer::GltfWriter)| {
        let mut w = good_gltf();
        f(&mut w);
        w.to_gltf()
    };
    let mut nan_position = good_gltf();
    nan_position.bin[0..4].copy_from_slice(&f32::NAN.to_le_bytes());
    let glb = good.to_glb();
    let mut glb_without_bin = glb.clone();
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    glb_without_bin.truncate(20 + json_len);
    let total = glb_without_bin.len() as u32;
    glb_without_bin[8..12].copy_from_slice(&total.to_le_bytes());
    vec![
        (Vec::new(), "gltf", "the file is empty"),
        (b"{".to_vec(), "gltf", "not a readable glTF"),
        (b"[1, 2, 3]".to_vec(), "gltf", "not a readable glTF"),
        (b"\x00\x01\x02garbage".to_vec(), "glb", "not a readable glTF"),
        (glb[..40].to_vec(), "glb", "not a readable glTF"),
        // Found by the fuzzer: a GLB header length below the header's own size.
        ([&glb[..8], &[0u8; 4][..], &glb[12..]].concat(), "glb", "the GLB header says 0 bytes"),
        ([&glb[..4], &[1u8, 0, 0, 0][..], &glb[8..]].concat(), "glb", "GLB version 1"),
        (glb_without_bin, "glb", "GLB binary chunk"),
        (text(&good)[..60].to_vec(), "gltf", "not a readable glTF"),
        (edit(&|w| w.json["asset"] = json!({})), "gltf", "missing field `version`"),
        (edit(&|w| w.json["accessors"][0]["count"] = json!(1000)), "gltf", "need"),
        (edit(&|w| w.json["accessors"][0]["byteOffset"] = json!(44)), "gltf", "need"),
        (edit(&|w| w.json["bufferViews"][0]["byteStride"] = json!(4)), "gltf", "stride"),
        (edit(&|w| w.json["bufferViews"][0]["byteLength"] = json!(100000)), "gltf", "outside its buffer"),
        (edit(&|w| w.json["bufferViews"][0]["byteOffset"] = json!(4000000000u64)), "gltf", "outside its buffer"),
        (
            edit(&|w| w.json["buffers"] = json!([{ "byteLength": 10_000_000_000u64, "uri": "data:application/octet-stream;base64,AAAA" }])),
            "gltf",
            "more than the",
        ),
        (
            edit(&|w| w.json["buffers"] = json!([{ "byteLength": 64, "uri": "data:application/octet-stream;base64,AAAA" }])),
            "gltf",
            "holds 3 bytes but claims 64",
        ),
        (
            edit(&|w| w.json["buffers"] = json!([{ "byteLength": 64, "uri": "data:application/octet-stream;base64,@@@" }])),
            "gltf",
            "bad base64",
        ),
        (edit(&|w| w.json["buffers"] = json!([{ "byteLength": 64, "uri": "missing.bin" }])), "gltf", "cannot read it"),
        (edit(&|w| w.json["buffers"] = json!([{ "byteLength": 64, "uri": "https://example.com/a.bin" }])), "gltf", "never downloads"),
        (edit(&|w| w.json["bufferViews"][0]["buffer"] = json!(5)), "gltf", "invalid glTF: bufferViews[0].buffer"),
        (edit(&|w| w.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(99)), "gltf", "POSITION names accessor 99"),
        (edit(&|w| w.json["meshes"][0]["primitives"][0]["attributes"] = json!({})), "gltf", "POSITION\"]: Missing data"),
        (edit(&|w| w.json["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = json!(2)), "gltf", "NORMAL: expected Vec3"),
        (edit(&|w| w.json["accessors"][3]["componentType"] = json!(5122)), "gltf", "not an index type"),
        (edit(&|w| w.json["accessors"][3]["count"] = json!(5)), "gltf", "whole triangles"),
        (edit(&|w| w.json["accessors"][1]["count"] = json!(3)), "gltf", "entries but POSITION has 4"),
        (
            edit(&|w| {
                w.json["accessors"][0]["sparse"] =
                    json!({ "count": 1, "indices": { "bufferView": 0, "componentType": 5125 }, "values": { "bufferView": 0 } })
            }),
            "gltf",
            "sparse",
        ),
        // Indices follow 4 positions, 4 normals and 4 texture coordinates (128 bytes).
        (
            edit(&|w| {
                w.bin[128..130].copy_from_slice(&9u16.to_le_bytes());
            }),
            "gltf",
            "only 4 vertices",
        ),
        (nan_position.to_gltf(), "gltf", "not finite"),
        (edit(&|w| w.json["extensionsRequired"] = json!(["KHR_draco_mesh_compression"])), "gltf", "KHR_draco_mesh_compression"),
        (edit(&|w| w.json["nodes"][0]["children"] = json!([0])), "gltf", "deeper than"),
        (edit(&|w| w.json["nodes"][0]["matrix"] = json!([1e39, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])), "gltf", "not finite"),
        (
            edit(&|w| {
                w.json["materials"] = json!([{ "pbrMetallicRoughness": { "metallicFactor": 2.0 } }]);
                w.json["meshes"][0]["primitives"][0]["material"] = json!(0);
            }),
            "gltf",
            "metallic factor 2",
        ),
        (
            edit(&|w| {
                let c = w.camera(json!({ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 1.0, "zfar": 0.5 } }));
                w.node(json!({ "camera": c }), true);
            }),
            "gltf",
            "0 < znear < zfar",
        ),
        (edit(&|w| w.json["meshes"][0]["primitives"][0]["mode"] = json!(0)), "gltf", "no triangles"),
        (edit(&|w| w.json["extensions"]["KHR_lights_punctual"]["lights"][0]["range"] = json!(-1.0)), "gltf", "range -1"),
        (
            edit(&|w| {
                w.json["extensions"]["KHR_lights_punctual"]["lights"][0] =
                    json!({ "type": "spot", "spot": { "innerConeAngle": 0.9, "outerConeAngle": 0.5 } })
            }),
            "gltf",
            "need 0 ≤ inner < outer ≤ π/2",
        ),
        (edit(&|w| w.json["scenes"][0]["nodes"] = json!([])), "gltf", "no triangles"),
        // Textures: an image with no source (the gltf crate's own accessor panics on it), a
        // buffer view without a MIME type, bytes that are no image, a PNG claiming 10⁵ pixels a side.
        (textured(&|w| w.json["images"][0] = json!({})), "gltf", "needs either a uri or a bufferView"),
        (textured(&|w| w.json["images"][0] = json!({ "bufferView": 0 })), "gltf", "without a mimeType"),
        (textured(&|w| w.json["images"][0] = json!({ "uri": "data:image/png;base64,AAAA" })), "gltf", "cannot decode"),
        (
            textured(&|w| {
                let mut huge = ml_cpu::gltf_writer::png(1, 1, &[0, 0, 0, 255]);
                huge[16..20].copy_from_slice(&100_000u32.to_be_bytes());
                let t = w.texture(huge, "image/png");
                w.json["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": t });
            }),
            "gltf",
            "cannot decode",
        ),
        // The other material textures go through the same checks; their factors are checked.
        (
            textured(&|w| {
                w.json["materials"][0]["occlusionTexture"] = json!({ "index": 0 });
                w.json["images"][0] = json!({});
            }),
            "gltf",
            "needs either a uri or a bufferView",
        ),
        (textured(&|w| w.json["materials"][0]["emissiveFactor"] = json!([2.0, 0.0, 0.0])), "gltf", "emissive factor 2"),
        (textured(&|w| w.json["materials"][0]["normalTexture"] = json!({ "index": 0, "scale": 1e39 })), "gltf", "normal scale inf"),
        (textured(&|w| w.json["samplers"] = json!([{ "wrapS": 12345 }])), "gltf", "invalid glTF"),
        // Sparse accessors: an index past the end, indices that do not rise, values cut short.
        (edit(&|w| w.sparse(0, &[99], &[[0.0; 3]])), "gltf", "sparse index 0 is 99"),
        (edit(&|w| w.sparse(0, &[2, 1], &[[0.0; 3], [1.0; 3]])), "gltf", "sparse index 1 is 1; they must rise"),
        (
            edit(&|w| {
                w.sparse(0, &[1], &[[0.0; 3]]);
                w.json["accessors"][0]["sparse"]["count"] = json!(3);
            }),
            "gltf",
            "the sparse indices (6 bytes at 0) lie outside",
        ),
        (
            edit(&|w| {
                let c =
                    w.camera(json!({ "type": "orthographic", "orthographic": { "xmag": 1.0, "ymag": 0.0, "znear": 0.1, "zfar": 9.0 } }));
                w.node(json!({ "camera": c }), true);
            }),
            "gltf",
            "need ymag > 0",
        ),
    ]
}

/// Every broken glTF (made above from a good one) ends the run with one error line naming the
/// file and the problem, exit code 1, no PNG; a directory named .gltf too.
#[test]
fn broken_gltf_files_are_refused_one_line_each() {
    let png = temp_png("never-gltf.png");
    let p = png.to_str().unwrap();
    let cases = broken_gltf_files();
    assert!(cases.len() + broken_scene_files().len() >= 40);
    let mut wrong = Vec::new();
    for (i, (bytes, ext, expected)) in cases.into_iter().enumerate() {
        let file = temp_png(&format!("broken-{i}.{ext}"));
        std::fs::write(&file, &bytes).unwrap();
        let out = manylights(&["render", "--scene", file.to_str().unwrap(), "--out", p], &[]);
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        let one_line = stderr.lines().count() == 1 && stderr.starts_with("error: ") && !stderr.contains("panicked");
        if !(one_line && stderr.contains(expected) && stderr.contains(file.to_str().unwrap()) && out.status.code() == Some(1)) {
            wrong.push(format!("case {i} (expected '{expected}', exit 1): exit {:?}: {stderr}", out.status.code()));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    let dir = temp_png("folder.gltf");
    std::fs::create_dir_all(&dir).unwrap();
    assert_one_line_error(&manylights(&["render", "--scene", dir.to_str().unwrap(), "--out", p], &[]), &["a directory"]);
    assert!(!png.exists());
}

/// The good file renders (validation on), with pbr by default.
#[test]
fn a_gltf_file_renders() {
    let file = temp_png("good.glb");
    std::fs::write(&file, good_gltf().to_glb()).unwrap();
    let png = temp_png("good-gltf.png");
    let out = manylights(
        &["render", "--validation", "--scene", file.to_str().unwrap(), "--width", "64", "--height", "48", "--out", png.to_str().unwrap()],
        &[],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("pbr") && png.exists(), "{stdout}");
}

/// `--technique auto` probes the device, names the technique it picked and why, and renders
/// exactly what that technique renders.
#[test]
fn auto_renders_what_it_picked() {
    let (auto_png, picked_png) = (temp_png("auto.png"), temp_png("picked.png"));
    // One rasteriser for both runs where auto picks visibility: `--raster auto` could time them
    // the other way round (auto takes the option, and warns where its pick has no rasteriser).
    let common = ["render", "--validation", "--scene", "bench", "--lights", "300", "--width", "96", "--height", "54", "--time", "0"];
    let raster = ["--raster", "hardware"];
    let out = manylights(&[&common[..], &raster, &["--technique", "auto", "--out", auto_png.to_str().unwrap()]].concat(), &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let technique_row = stdout.lines().find(|l| l.starts_with("technique")).expect("a technique row");
    let picked = technique_row.split_whitespace().nth(1).unwrap().to_owned();
    assert!(
        technique_row.ends_with("(auto)") && ["visibility", "deferred-compute", "deferred-clustered"].contains(&picked.as_str()),
        "{stdout}"
    );
    let why = stdout.lines().find(|l| l.starts_with("auto")).expect("an auto row");
    assert!(why.contains("as a fragment shader") && why.contains("as a compute shader"), "{why}");
    // --aa auto is the default: off on a CPU driver, samples on a GPU, said why.
    let aa = stdout.lines().find(|l| l.starts_with("auto aa")).expect("an auto aa row");
    let cpu = stdout.lines().any(|l| l.starts_with("device") && l.contains("(CPU"));
    assert!(if cpu { aa.contains("off: a CPU driver") } else { aa.contains(": a GPU") }, "{aa}");
    // --raster compute given and auto's pick without a visibility buffer: said to be unused,
    // and only that (the render draws with the hardware).
    let compute = ["--raster", "compute", "--technique", "auto", "--out", picked_png.to_str().unwrap()];
    let out = manylights(&[&common[..], &compute].concat(), &[]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{stderr}");
    let technique = stdout.lines().find(|l| l.starts_with("technique")).expect("a technique row");
    assert!(technique.contains("visibility") || stderr.contains("--raster is not used"), "{technique}: {stderr}");
    let raster: &[&str] = if picked == "visibility" { &raster } else { &[] };
    let out = manylights(&[&common[..], raster, &["--technique", &picked, "--out", picked_png.to_str().unwrap()]].concat(), &[]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (a, b) = (image::open(&auto_png).unwrap().to_rgba8(), image::open(&picked_png).unwrap().to_rgba8());
    assert!(a == b, "auto's image differs from {picked}'s");
}

/// `--raster auto` renders the scene with each rasteriser (hardware, hybrid, compute), keeps
/// the first of compute, hybrid, hardware whose frames took within 10 % of the least time, and
/// says so with every time; a rasteriser the settings cannot take is one error line.
#[test]
fn raster_auto_keeps_the_faster_and_says_why() {
    let png = temp_png("raster-auto.png");
    let args = ["render", "--validation", "--scene", "bench", "--objects", "40", "--lights", "200", "--width", "96", "--height", "54"];
    let out = manylights(&[&args[..], &["--technique", "visibility", "--raster", "auto", "--out", png.to_str().unwrap()]].concat(), &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let why = stdout.lines().find(|l| l.starts_with("auto raster")).expect("an auto raster row");
    let ms = |name: &str| -> f64 {
        let head = &why[..why.find(&format!(" ms {name}")).unwrap_or_else(|| panic!("{why}"))];
        head.split_whitespace().next_back().unwrap().parse().unwrap_or_else(|_| panic!("{why}"))
    };
    // In the order of preference: the first within 10 % of the fastest is kept.
    let times = ["compute", "hybrid", "hardware"].map(|name| (ms(name), name));
    let raster = stdout.lines().find(|l| l.starts_with("raster ")).expect("a raster row");
    let fastest = times.iter().map(|t| t.0).fold(f64::INFINITY, f64::min);
    let kept = times.iter().find(|t| t.0 <= fastest * 1.1).unwrap().1;
    assert!(raster.split_whitespace().nth(1) == Some(kept) && raster.ends_with("(auto)"), "{raster} ({why})");
    assert!(why.contains("medians of 3 frames after a warm-up") && why.contains("within 10 % of the fastest"), "{why}");
    for (extra, needles) in [
        (&["--technique", "forward", "--raster", "compute"][..], &["--raster does not apply to forward", "--technique visibility"][..]),
        (&["--technique", "visibility", "--raster", "compute", "--raster-split", "0"][..], &["--raster-split 0", "1 to 64"][..]),
        (&["--technique", "visibility", "--raster", "sideways"][..], &["sideways"][..]),
    ] {
        let out = manylights(&[&args[..], extra, &["--out", png.to_str().unwrap()]].concat(), &[]);
        assert_one_line_error(&out, needles);
    }
    // 8 bytes a pixel in one storage buffer: more than any device we run allows (lavapipe:
    // 128 MiB, the H100: 4 GiB).
    let huge = ["render", "--technique", "visibility", "--raster", "compute", "--width", "16384", "--height", "16384"];
    let out = manylights(&[&huge[..], &["--out", png.to_str().unwrap()]].concat(), &[]);
    assert_one_line_error(&out, &["16384x16384", "bytes", "--raster hardware"]);
}

/// A scene that never ends or never comes — a link x.glb to /dev/zero, z.gltf to /dev/urandom,
/// a named pipe y.toml no one writes to — ends the run at once with one error line naming it:
/// read whole, a device would fill the memory, and a pipe would wait forever.
#[cfg(unix)]
#[test]
fn scenes_on_devices_and_pipes_are_refused_at_once() {
    let dir = temp_png("devices-and-pipes");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (zero, random, pipe) = (dir.join("x.glb"), dir.join("z.gltf"), dir.join("y.toml"));
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    std::os::unix::fs::symlink("/dev/urandom", &random).unwrap();
    assert!(Command::new("mkfifo").arg(&pipe).status().expect("mkfifo runs").success());
    let png = dir.join("never.png");
    for scene in [&zero, &random, &pipe] {
        let start = std::time::Instant::now();
        let out = manylights(&["render", "--scene", scene.to_str().unwrap(), "--out", png.to_str().unwrap()], &[]);
        let took = start.elapsed();
        assert!(took.as_secs_f32() < 5.0, "{}: {took:?}", scene.display());
        assert_one_line_error(&out, &[scene.to_str().unwrap(), "it is not a regular file (a device, pipe or socket)"]);
        assert_eq!(out.status.code(), Some(1), "{}", scene.display());
    }
    assert!(!png.exists());
}

#[test]
fn transparent_layers_report_their_memory_and_what_did_not_fit() {
    let png = temp_png("glass.png");
    let render = |extra: &[&str]| {
        let mut args = vec!["render", "--validation", "--width", "64", "--height", "36", "--out", png.to_str().unwrap()];
        args.extend_from_slice(&["--technique", "deferred-clustered"]);
        args.extend_from_slice(extra);
        manylights(&args, &[])
    };
    // Six panes on every pixel, room for eight: all kept, the table says so, no warning.
    let out = render(&["--glass-layers", "6", "--transparency-budget", "8"]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{stdout}{stderr}");
    for row in ["transparent layers pass", "transparent resolve pass", "13824 fragments (6.00 a pixel)", "0 fragments dropped"] {
        assert!(stdout.contains(row), "'{row}' missing from:\n{stdout}");
    }
    assert!(!stderr.contains("transparent layers"), "{stderr}");
    // Room for two: the rest dropped, counted in the table and said in a warning.
    let out = render(&["--glass-layers", "6", "--transparency-budget", "2"]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{stdout}{stderr}");
    assert!(stdout.contains("9216 fragments dropped"), "{stdout}");
    let warning = |stderr: &str| -> Vec<String> {
        stderr.lines().filter(|l| l.starts_with("warning: the transparent layers")).map(str::to_owned).collect()
    };
    assert_eq!(
        warning(&stderr),
        ["warning: the transparent layers are not exact: 9216 fragments dropped, the pool of 4608 nodes full (raise --transparency-budget)"],
        "{stderr}"
    );
    // Forty panes with room for all: nothing dropped, the farthest 8 of each pixel merged —
    // and the warning says that, and only that.
    let out = render(&["--glass-layers", "40", "--transparency-budget", "48"]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{stdout}{stderr}");
    assert!(stdout.contains("0 fragments dropped (pool full), 2304 pixels over 32 layers"), "{stdout}");
    assert_eq!(
        warning(&stderr),
        ["warning: the transparent layers are not exact: 2304 pixels had more than 32 layers, the farthest merged into one layer behind the nearest 32 (their order lost)"],
        "{stderr}"
    );
    // Without transparent objects the budget and the layer view do not apply.
    for option in [&["--transparency-budget", "8"][..], &["--debug-view", "transparency-layers"]] {
        let mut args = vec!["render", "--width", "64", "--height", "36", "--out", png.to_str().unwrap()];
        args.extend_from_slice(option);
        let out = manylights(&args, &[]);
        assert_one_line_error(&out, &["no transparent objects", option[0]]);
    }
}

#[test]
fn light_stats_print_a_row_where_the_lighting_is_in_compute() {
    let png = temp_png("light_stats.png");
    let args = |technique: &'static str| {
        ["render", "--validation", "--width", "64", "--height", "36", "--scene", "bench", "--lights", "2048", "--light-stats"]
            .into_iter()
            .chain(["--technique", technique, "--out", png.to_str().unwrap()])
            .collect::<Vec<&str>>()
    };
    let out = manylights(&args("deferred-compute"), &[]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{stdout}{stderr}");
    let row = stdout.lines().find(|l| l.starts_with("lights per pixel")).unwrap_or_else(|| panic!("no light row in:\n{stdout}"));
    assert!(row.contains(" tested, ") && row.contains(" reaching (") && row.contains("pixels with a surface)"), "{row}");
    // The fragment techniques' loops are not counted: refused in one line.
    assert_one_line_error(&manylights(&args("forward"), &[]), &["--light-stats", "forward"]);
}

/// lavapipe compiles shaders for a vector width (256 bits with AVX, 128 without, or what
/// `LP_NATIVE_VECTOR_WIDTH` says) and keeps them in a disk cache that does not know the width:
/// code of one width loaded at the other overruns the draw's vertex outputs and kills the
/// process (ml_vk::driver_env). Three techniques — between them every kind of pipeline: a
/// forward draw, deferred's two subpasses, the visibility technique's compute passes — draw the
/// teapot at 256 bits and then at 128 bits with one cache folder named for both, with
/// validation, and the two images are the same but for rounding. On a GPU the variables change
/// nothing and the images are equal.
#[test]
fn the_teapot_renders_at_either_vector_width_from_one_shader_cache() {
    let dir = temp_png("vector-width").with_file_name("vector-width");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let cache = dir.join("shader-cache");
    for technique in ["forward", "deferred", "visibility"] {
        let images = ["256", "128"].map(|width| {
            let png = dir.join(format!("{technique}-{width}.png"));
            let args = ["render", "--validation", "--object", "teapot", "--technique", technique, "--time", "0"];
            let size = ["--width", "96", "--height", "64", "--out", png.to_str().unwrap()];
            let env = [("LP_NATIVE_VECTOR_WIDTH", width), ("MESA_SHADER_CACHE_DIR", cache.to_str().unwrap())];
            let out = manylights(&[&args[..], &size].concat(), &env);
            let say = |o: &Output| format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
            assert!(out.status.success(), "{technique} at {width} bits: {:?}\n{}", out.status, say(&out));
            image::open(&png).expect("a PNG").to_rgba8().into_raw()
        });
        let (worst, moved) = common::rgba_difference(&images[0], &images[1]);
        println!("{technique}: 256 against 128 bits: {moved} pixels differ, by up to {worst}/255");
        assert!(worst <= 2 && moved <= 96 * 64 / 100, "{technique}: {moved} pixels differ, by up to {worst}/255");
    }
}
