//! The command line: a good render prints its table and writes its PNG; bad input gets one
//! clear error line and a non-zero exit, never a panic.

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

/// Fails unless the run failed with exactly one `error:` line mentioning every `needle`.
fn assert_one_line_error(out: &Output, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "should fail; stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "expected one line, got: {stderr}");
    assert!(lines[0].starts_with("error: "), "{stderr}");
    for n in needles {
        assert!(lines[0].contains(n), "'{n}' missing from: {stderr}");
    }
}

#[test]
fn renders_a_png_and_prints_the_table() {
    let png = temp_png("ok.png");
    let out =
        manylights(&["render", "--validation", "--width", "64", "--height", "36", "--time", "0", "--out", png.to_str().unwrap()], &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    for key in ["device", "resolution", "64x36", "lights", "gpu ms", "cpu ms/frame"] {
        assert!(stdout.contains(key), "'{key}' missing from:\n{stdout}");
    }
    let img = image::open(&png).expect("a PNG").to_rgba8();
    assert_eq!(img.dimensions(), (64, 36));
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
    for key in ["blinn-phong", "g-buffer + lighting pass", "tone map pass", "16 bytes/pixel", "transient"] {
        assert!(stdout.contains(key), "'{key}' missing from:\n{stdout}");
    }
}

#[test]
fn absurd_sizes_and_counts_are_refused() {
    let png = temp_png("never2.png");
    let p = png.to_str().unwrap();
    assert_one_line_error(&manylights(&["render", "--lights", "0", "--out", p], &[]), &["--lights 0"]);
    assert_one_line_error(&manylights(&["render", "--lights", "100000000", "--out", p], &[]), &["--lights 100000000", "16777216"]);
    assert_one_line_error(&manylights(&["render", "--width", "0", "--out", p], &[]), &["--width 0"]);
    assert_one_line_error(&manylights(&["render", "--height", "100000", "--out", p], &[]), &["--height 100000"]);
    assert_one_line_error(&manylights(&["render", "--frames", "0", "--out", p], &[]), &["--frames"]);
    let omni = |k: &str, size: &str| {
        manylights(&["render", "--omni-shadow", "direct", "--shadowed-lights", k, "--cube-size", size, "--out", p], &[])
    };
    assert_one_line_error(&omni("65", "64"), &["--shadowed-lights 65", "64 lights"]);
    assert_one_line_error(&omni("0", "64"), &["--shadowed-lights 0"]);
    assert_one_line_error(&omni("1", "0"), &["--cube-size 0"]);
    assert_one_line_error(&omni("64", "8192"), &["shadow cubes", "MiB"]);
    assert!(!png.exists());
}

#[test]
fn unwritable_output_is_refused_before_rendering() {
    let missing = std::env::temp_dir().join("manylights-no-such-folder/a.png");
    assert_one_line_error(&manylights(&["render", "--out", missing.to_str().unwrap()], &[]), &["does not exist"]);
    let dir = std::env::temp_dir();
    assert_one_line_error(&manylights(&["render", "--out", dir.to_str().unwrap()], &[]), &["directory"]);
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
        ("[[objects]]\nmesh = \"sphere\"\n[[lights]]\ncolor = [1.0, 1.0, 1.0]\n", "missing field `position`"),
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
