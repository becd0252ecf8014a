//! Hostile input on the command line: argument errors keep clap's whole message (what is
//! missing or wrong, the tip, the usage) on one line with exit code 2, counts are refused
//! with their range, options given that do not apply to the technique or scene are refused
//! naming what they need, and every option's help has a description and its default said one
//! way. Most runs here fail before any GPU work.

use crate::common;

use common::{assert_one_line_error, manylights};
use std::path::{Path, PathBuf};
use std::process::Output;

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("arguments", name)
}

/// One error line with every needle, and exit code 2: an argument clap refused.
fn assert_argument_error(out: &Output, needles: &[&str]) {
    assert_one_line_error(out, needles);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn argument_errors_keep_what_is_wrong_the_tip_and_the_usage() {
    assert_argument_error(&manylights(&["render"]), &["--out", "not provided", "Usage: manylights render"]);
    assert_argument_error(&manylights(&["render", "--lihgts", "5", "--out", "a.png"]), &["'--lihgts'", "similar argument", "'--lights'"]);
    assert_argument_error(&manylights(&["bench", "--framse", "3"]), &["'--framse'", "similar argument", "'--frames'"]);
    assert_argument_error(&manylights(&["rendr"]), &["'rendr'", "similar subcommand", "'render'"]);
    assert_argument_error(&manylights(&["render", "--culling", "maybe", "--out", "a.png"]), &["'maybe'", "--culling", "on, off"]);
}

/// A bare `manylights` prints the help and, as its one error line, the commands.
#[test]
fn a_bare_manylights_prints_the_help_and_names_the_commands() {
    let out = manylights(&[]);
    assert_argument_error(&out, &["render", "view", "bench", "info"]);
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(help.contains("Usage: manylights <COMMAND>") && help.contains("Render a scene headless"), "{help}");
}

#[test]
fn negative_and_huge_counts_get_their_range() {
    let render = |flag: &str, value: &str| manylights(&["render", flag, value, "--out", "a.png"]);
    assert_argument_error(&render("--width", "-100"), &["--width -100 is out of range: use 1 to 16384"]);
    assert_argument_error(&render("--height", "99999999999999999999999"), &["--height 99999999999999999999999 is out of range"]);
    assert_argument_error(&render("--lights", "-5"), &["--lights -5 is out of range: use 1 to 67108864"]);
    assert_argument_error(&render("--frames", "-1"), &["--frames -1 is out of range: use 1 to 100000"]);
    assert_argument_error(&render("--raster-split", "-8"), &["--raster-split -8 is out of range: use 1 to 64"]);
    assert_argument_error(&render("--light-seed", "-1"), &["--light-seed -1 is out of range"]);
    assert_argument_error(&render("--device", "-1"), &["--device -1 is out of range"]);
    assert_argument_error(&render("--shadow-budget", "-5"), &["--shadow-budget -5 is out of range", "device's memory"]);
    assert_argument_error(&render("--width", "wide"), &["--width 'wide' is not a whole number"]);
    assert_argument_error(&render("--supersample", "17"), &["--supersample 17 is out of range: use 1 to 16"]);
    assert_argument_error(&render("--aa", "2"), &["'2'", "--aa", "off, 4, 8, 16"]);
    // Counts spelt as bench spells them, and sizes as WxH.
    assert_argument_error(&render("--lights", "100M"), &["--lights 100M is out of range: use 1 to 67108864"]);
    assert_argument_error(&render("--lights", "1.5k"), &["--lights '1.5k' is not a whole number"]);
    // A quoting slip is not a number: nothing around it.
    assert_argument_error(&render("--lights", " 5"), &["--lights ' 5' is not a whole number"]);
    assert_argument_error(&render("--width", "64 "), &["--width '64 ' is not a whole number"]);
    assert_argument_error(&render("--resolution", "0x5"), &["--resolution 0x5: each side must be 1 to 16384"]);
    let both = manylights(&["render", "--resolution", "64x36", "--width", "64", "--out", "a.png"]);
    assert_argument_error(&both, &["'--resolution <RESOLUTION>' cannot be used with '--width <WIDTH>'"]);
    // A folder named as the scene is said to be one.
    let folder = temp_dir("scene-folder");
    let scene = manylights(&["render", "--scene", folder.to_str().unwrap(), "--out", "a.png"]);
    assert_one_line_error(&scene, &["is a folder: name the scene file in it"]);
    let big = manylights(&["render", "--supersample", "9", "--width", "2000", "--out", "a.png"]);
    assert_one_line_error(&big, &["--supersample 9 renders 18000x", "more than 16384 pixels a side"]);
    let out = temp_dir("bench-counts");
    let bench = |args: &[&str]| manylights(&[&["bench", "--out", out.to_str().unwrap()], args].concat());
    // Once warm-up and measured frames were added in 32 bits: 2³² − 1 + 2 wrapped to 1.
    assert_argument_error(&bench(&["--warmup", "4294967295", "--frames", "2"]), &["--warmup 4294967295 is out of range: use 0 to 100000"]);
    assert_argument_error(&bench(&["--frames", "0"]), &["--frames 0 is out of range: use 1 to 100000"]);
    assert_argument_error(&bench(&["--probe", "--warmup", "-1"]), &["--warmup -1 is out of range"]);
    assert_one_line_error(&bench(&["--budget-s", "-1"]), &["--budget-s -1 must be greater than 0"]);
    assert_one_line_error(&bench(&["--resolution", "-640x480"]), &["--resolution -640x480", "each side must be 1 to 16384"]);
    assert!(!out.join("results.csv").exists());
}

/// A scene file with a light of its own.
fn lit_scene_file(dir: &Path) -> PathBuf {
    let path = dir.join("lit.toml");
    std::fs::write(&path, "[[objects]]\nmesh = \"sphere\"\n\n[[lights]]\nposition = [0.0, 3.0, 0.0]\n").unwrap();
    path
}

/// Each option that does nothing with the technique, the scene or the other settings asked
/// for is refused, naming the option, what it does not apply to and what it needs. The
/// technique is named, so that no probe runs: every refusal comes before any GPU work.
#[test]
fn options_that_do_not_apply_are_refused() {
    let dir = temp_dir("not-applying");
    let lit = lit_scene_file(&dir);
    let png = dir.join("never.png");
    let render = |args: &[&str]| manylights(&[&["render", "--out", png.to_str().unwrap()], args].concat());
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["--technique", "forward", "--clusters", "4x4x2"],
            &["--clusters does not apply to forward", "clustered-cpu", "deferred-clustered"],
        ),
        (&["--technique", "visibility", "--clusters", "4x4x2"], &["--clusters does not apply to visibility"]),
        (&["--technique", "deferred", "--clusters", "auto"], &["--clusters does not apply to deferred"]),
        (&["--technique", "forward", "--culling", "off"], &["--culling does not apply to forward", "--technique visibility"]),
        // Given explicitly, even with the default's value.
        (&["--technique", "deferred", "--culling", "on"], &["--culling does not apply to deferred"]),
        (&["--technique", "forward", "--raster", "hardware"], &["--raster does not apply to forward", "--technique visibility"]),
        (&["--technique", "clustered-gpu", "--raster-split", "8"], &["--raster-split does not apply to clustered-gpu"]),
        (&["--technique", "visibility", "--raster", "hardware", "--raster-split", "8"], &["--raster-split", "--raster hardware"]),
        (&["--technique", "deferred", "--debug-view", "aa"], &["--debug-view aa", "--technique visibility"]),
        (&["--technique", "forward", "--debug-view", "cluster-heat"], &["--debug-view cluster-heat", "clustered-cpu or clustered-gpu"]),
        (&["--technique", "deferred-compute", "--debug-view", "meshlets"], &["--debug-view meshlets", "--technique visibility"]),
        (&["--technique", "forward", "--debug-view", "shadow-atlas"], &["--debug-view shadow-atlas", "--omni-shadow atlas"]),
        (&["--technique", "forward", "--omni-shadow", "atlas", "--debug-view", "shadow-cube"], &["--debug-view shadow-cube", "layered"]),
        (&["--technique", "forward", "--debug-view", "shadow-map"], &["--debug-view shadow-map", "seed shading model", "blinn-phong"]),
        (&["--technique", "forward", "--sun-shadow", "compute"], &["--sun-shadow", "seed shading model", "--shading blinn-phong"]),
        (&["--technique", "forward", "--debug-view", "depth", "--exposure", "1"], &["--exposure does not apply to --debug-view depth"]),
        (&["--technique", "forward", "--objects", "10"], &["--objects does not apply to --scene seed", "--scene bench"]),
        (
            &["--technique", "forward", "--scene", "bench", "--object", "teapot"],
            &["--object does not apply to --scene bench", "--scene seed"],
        ),
        (&["--technique", "forward", "--scene", "room", "--material", "red"], &["--material does not apply to --scene room"]),
        (&["--technique", "forward", "--scene", "room", "--lights", "8"], &["--lights does not apply to --scene room"]),
        (&["--technique", "forward", "--scene", "bench", "--light-layout", "grid"], &["--light-layout does not apply to --scene bench"]),
        (&["--technique", "forward", "--scene", "bench", "--light-radius", "2"], &["--light-radius does not apply to --scene bench"]),
        (&["--technique", "forward", "--light-seed", "7"], &["--light-seed", "--light-layout grid", "random"]),
        (&["--technique", "forward", "--scene", "room", "--light-seed", "7"], &["--light-seed does not apply to --scene room"]),
        (
            &["--technique", "forward", "--scene", lit.to_str().unwrap(), "--light-layout", "random"],
            &["--light-layout", "lit.toml", "--lights N"],
        ),
        (&["--technique", "forward", "--shadowed-lights", "1"], &["--shadowed-lights does not apply to --omni-shadow off"]),
        (&["--technique", "forward", "--cube-size", "64"], &["--cube-size does not apply to --omni-shadow off"]),
        (&["--technique", "forward", "--omni-shadow", "direct", "--shadow-budget", "64"], &["--shadow-budget", "--omni-shadow direct"]),
        (&["--technique", "forward", "--omni-shadow", "layered", "--shadow-cache", "off"], &["--shadow-cache", "--omni-shadow atlas"]),
        // With auto, an option that applies to none of auto's picks is refused before the probe.
        (&["--debug-view", "cluster-heat"], &["--debug-view cluster-heat does not apply to auto", "rather than auto"]),
    ];
    for (args, needles) in cases {
        let start = std::time::Instant::now();
        assert_one_line_error(&render(args), needles);
        assert!(start.elapsed().as_secs() < 20, "{args:?}: refused only after {:?}", start.elapsed());
    }
    // The viewer, before its window opens.
    assert_one_line_error(&manylights(&["view", "--technique", "forward", "--culling", "off"]), &["--culling does not apply to forward"]);
    // bench: an option applies where one of the techniques takes it; --probe renders none.
    let out = dir.join("bench");
    let bench = |args: &[&str]| manylights(&[&["bench", "--out", out.to_str().unwrap()], args].concat());
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["--techniques", "forward,deferred", "--clusters", "4x4x2"],
            &["--clusters does not apply to forward and deferred", "--techniques"],
        ),
        (&["--techniques", "forward", "--raster", "compute"], &["--raster does not apply to forward", "--techniques visibility"]),
        (&["--raster", "hardware", "--raster-split", "8"], &["--raster-split does not apply to --raster hardware"]),
        (&["--probe", "--techniques", "forward"], &["--techniques does not apply to bench --probe"]),
        (&["--probe", "--lights", "1k"], &["--lights does not apply to bench --probe"]),
        (&["--probe-lights", "16"], &["--probe-lights does not apply to bench without --probe", "--probe"]),
        (&["--scene", "seed", "--objects", "10"], &["--objects does not apply to --scene seed"]),
    ];
    for (args, needles) in cases {
        assert_one_line_error(&bench(args), needles);
    }
    assert!(!png.exists() && !out.join("results.csv").exists());
}

/// Options left to their defaults are never refused: a run with every default gets past the
/// checks to the output's (whose folder does not exist), still before any GPU work.
#[test]
fn defaults_never_count_as_given() {
    let missing = std::env::temp_dir().join("manylights-arguments-no-such-folder/a.png");
    for args in
        [&["--technique", "forward"][..], &["--technique", "deferred", "--scene", "room"], &["--technique", "forward", "--scene", "bench"]]
    {
        let out = manylights(&[&["render", "--out", missing.to_str().unwrap()], args].concat());
        assert_one_line_error(&out, &["does not exist"]);
    }
}

/// With auto, an option that applies to some of its picks is taken: the run renders, with it
/// where the pick uses it, and with a warning naming the pick where it does not (the same
/// command line works on every device).
#[test]
fn auto_takes_what_one_of_its_picks_uses() {
    let png = temp_dir("auto").join("culling.png");
    let out = manylights(&["render", "--culling", "off", "--width", "32", "--height", "18", "--out", png.to_str().unwrap()]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success() && png.exists(), "{stdout}{stderr}");
    let visibility = stdout.lines().any(|l| l.starts_with("technique") && l.contains("visibility"));
    let warned = stderr.lines().any(|l| l.starts_with("warning: --culling is not used: auto picked"));
    assert!(visibility != warned, "{stdout}{stderr}");
}

/// The options of a command's `--help`: (flag, its whole entry).
fn help_entries(command: &str) -> Vec<(String, String)> {
    let out = manylights(&[command, "--help"]);
    assert!(out.status.success());
    let help = String::from_utf8(out.stdout).unwrap();
    let options = help.split_once("\nOptions:\n").unwrap_or_else(|| panic!("{help}")).1;
    let mut entries: Vec<(String, String)> = Vec::new();
    for line in options.lines() {
        let text = line.trim_start();
        let indent = line.len() - text.len();
        if text.starts_with('-') && indent < 8 {
            let flag = text.split_whitespace().find(|w| w.starts_with("--")).unwrap().trim_end_matches(',').to_owned();
            // A short help has the description on the same line, after two spaces or more.
            let description = text.split_once("  ").map_or("", |(_, d)| d.trim());
            entries.push((flag, format!("{description} ")));
        } else if let Some((_, entry)) = entries.last_mut() {
            *entry += text;
            *entry += " ";
        }
    }
    entries
}

/// Every option has a description, and says its default at most once, one way: clap's
/// `[default: X]` or a sentence `Default: …`, no other word for it.
#[test]
fn every_option_has_a_description_and_one_default() {
    for command in ["render", "view", "bench"] {
        let entries = help_entries(command);
        assert!(entries.len() > 10, "{command}: {entries:?}");
        for (flag, text) in &entries {
            let description = text.split(" [").next().unwrap().trim();
            assert!(!description.is_empty(), "{command} {flag} has no description");
            let said = text.to_lowercase().matches("default").count();
            let marked = text.matches("[default: ").count() + text.matches("Default: ").count();
            assert!(said == marked && marked <= 1, "{command} {flag} says its default {said} times, {marked} of them marked: {text}");
        }
    }
}

/// The names an unknown-name error lists ("…: expected one of a, b, c").
fn accepted(error: impl std::fmt::Display) -> Vec<String> {
    let text = error.to_string();
    let list = text.split_once("expected one of ").unwrap_or_else(|| panic!("{text}")).1;
    list.split(", ").map(str::to_owned).collect()
}

/// Every name the code accepts for an option appears in its help.
#[test]
fn the_help_lists_every_accepted_value() {
    use ml_render::{DebugView, OmniShadowMode, Raster, SunShadowMode, Technique};
    let with = |mut names: Vec<String>, more: &[&str]| {
        names.extend(more.iter().map(|m| m.to_string()));
        names
    };
    let techniques = with(accepted(Technique::from_name("?").unwrap_err()), &["auto"]);
    let rasters = accepted(Raster::from_name("?", 16).unwrap_err());
    let shading = accepted(ml_cpu::shading_model::ShadingModel::from_name("?").unwrap_err());
    let scene_options = [
        ("--technique", techniques.clone()),
        ("--shading", shading.clone()),
        ("--debug-view", accepted(DebugView::from_name("?").unwrap_err())),
        ("--omni-shadow", with(accepted(OmniShadowMode::from_name("?").unwrap_err()), &["off"])),
        ("--sun-shadow", accepted(SunShadowMode::from_name("?").unwrap_err())),
        ("--object", accepted(ml_cpu::mesh::MeshKind::from_name("?").unwrap_err())),
        ("--material", accepted(ml_cpu::material::Material::named("?").unwrap_err())),
        ("--light-layout", accepted(ml_cpu::lights::LightLayout::from_name("?").unwrap_err())),
        ("--raster", with(rasters.clone(), &["auto"])),
        ("--scene", vec!["seed".into(), "room".into(), "bench".into()]),
    ];
    let bench_options = [("--techniques", techniques), ("--raster", rasters), ("--shading", shading)];
    for (command, options) in [("render", &scene_options[..]), ("view", &scene_options[..]), ("bench", &bench_options[..])] {
        let entries = help_entries(command);
        for (flag, names) in options {
            let (_, text) = entries.iter().find(|(f, _)| f == flag).unwrap_or_else(|| panic!("{command}: no {flag}"));
            let words: Vec<&str> = text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-')).collect();
            for name in names {
                assert!(words.contains(&name.as_str()), "{command} {flag}: '{name}' missing from: {text}");
            }
        }
    }
}

/// The documents the help points to exist, and the viewer's script format is in the one
/// `--script` names.
#[test]
fn the_help_points_to_documents_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    for command in ["render", "view", "bench"] {
        for (flag, text) in help_entries(command) {
            assert!(!text.contains("README"), "{command} {flag}: {text}");
            for doc in text.split_whitespace().filter_map(|w| w.find("docs/").map(|i| &w[i..])) {
                let doc = doc.trim_end_matches(|c: char| !c.is_ascii_alphanumeric());
                assert!(root.join(doc).is_file(), "{command} {flag} points to {doc}, which does not exist");
            }
        }
    }
    let (_, script) = help_entries("view").into_iter().find(|(f, _)| f == "--script").unwrap();
    assert!(script.contains("docs/usage.md"), "{script}");
    let usage = std::fs::read_to_string(root.join("docs/usage.md")).unwrap();
    // The script parser's own list of its commands.
    let error = ml_viewer::script::parse("teleport 3").unwrap_err();
    let commands = error.split_once('(').unwrap().1.trim_end_matches(')');
    for command in commands.split(", ") {
        assert!(usage.contains(&format!("`{command}`")), "docs/usage.md does not describe the script command `{command}`");
    }
}

/// The front door and the documents a newcomer reads first stay within what a reader reads:
/// README 10 KiB, docs/BENCHMARKS.md (current figures with their commands) 30 KiB,
/// docs/DESIGN.md (the reasoning) 40 KiB. A run's narrative belongs in its commit message.
#[test]
fn the_front_documents_stay_within_their_sizes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    for (doc, limit) in [("README.md", 10 << 10), ("docs/BENCHMARKS.md", 30 << 10), ("docs/DESIGN.md", 40 << 10)] {
        let bytes = std::fs::metadata(root.join(doc)).unwrap_or_else(|e| panic!("{doc}: {e}")).len();
        assert!(bytes <= limit, "{doc} is {bytes} bytes, more than its {limit}: cut it to what a reader needs now");
    }
}

/// `--variant` names a glTF file's material variant: refused for other scenes, and a name the
/// file lacks is refused with the names it has — each in one line, before any GPU work.
#[test]
fn a_material_variant_is_refused_where_there_is_none() {
    let dir = temp_dir("variant");
    let mut w = ml_cpu::gltf_writer::GltfWriter::new();
    let mesh = w.mesh(&[ml_cpu::gltf_writer::quad()]);
    w.node(serde_json::json!({ "mesh": mesh }), true);
    w.json["extensions"] = serde_json::json!({ "KHR_materials_variants": { "variants": [{ "name": "red" }] } });
    let file = dir.join("variants.glb");
    std::fs::write(&file, w.to_glb()).unwrap();
    let out = dir.join("out.png");
    let render =
        |scene: &str, variant: &str| manylights(&["render", "--scene", scene, "--variant", variant, "--out", out.to_str().unwrap()]);
    assert_one_line_error(&render("seed", "red"), &["--variant", "glTF file"]);
    assert_one_line_error(&render(file.to_str().unwrap(), "blue"), &["variants.glb", "no material variant 'blue'", "the file has red"]);
    assert!(!out.exists(), "nothing written");
}
