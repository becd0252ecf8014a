//! Environment light from the command line and scene files: an equirectangular .hdr lights a
//! pbr scene, with its intensity and turn, and shows behind it where asked; the table says
//! what was prefiltered; files that are not environments and options that cannot apply are
//! refused in one line.

use crate::common;

use common::{assert_one_line_error, manylights, rgba_difference};
use std::path::{Path, PathBuf};

const SIZE: [&str; 4] = ["--width", "64", "--height", "48"];

/// A pbr scene file: a metal sphere over a white floor, one light far from both (so the
/// environment is what lights them), and `extra` appended.
fn scene(dir: &Path, name: &str, extra: &str) -> PathBuf {
    let path = dir.join(name);
    let text = format!(
        "[shading]\nmodel = \"pbr\"\n\n[[objects]]\nmesh = \"sphere\"\nposition = [0.0, 1.0, 0.0]\nmaterial = {{ albedo = [0.9, 0.8, 0.6], roughness = 0.4, metallic = 1.0 }}\n\n\
         [[objects]]\nmesh = \"plane\"\nscale = 4.0\nmaterial = {{ name = \"white\" }}\n\n\
         [[lights]]\nposition = [90.0, 90.0, 90.0]\nradius = 1.0\ncolor = [1.0, 1.0, 1.0]\n\n{extra}"
    );
    std::fs::write(&path, text).unwrap();
    path
}

/// A 64×32 equirectangular Radiance file: warm on one side, blue on the other, brighter above
/// the horizon (so a turn shows).
fn hdr(path: &Path) {
    let texel = |i: usize| {
        let above = if i / 64 < 16 { 1.0 } else { 0.2 };
        image::Rgb(if i % 64 < 32 { [2.0, 1.2, 0.5] } else { [0.1, 0.2, 0.8] }.map(|c| c * above))
    };
    let texels: Vec<image::Rgb<f32>> = (0..64 * 32).map(texel).collect();
    let file = std::fs::File::create(path).unwrap();
    image::codecs::hdr::HdrEncoder::new(file).encode(&texels, 64, 32).unwrap();
}

fn render(args: &[&str]) -> (String, Vec<u8>) {
    let out_png = args[args.iter().position(|a| *a == "--out").unwrap() + 1];
    let mut all = vec!["render", "--validation", "--technique", "forward", "--exposure", "0"];
    all.extend(SIZE);
    all.extend(args);
    let run = manylights(&all);
    assert!(run.status.success(), "{}{}", String::from_utf8_lossy(&run.stdout), String::from_utf8_lossy(&run.stderr));
    (String::from_utf8_lossy(&run.stdout).into_owned(), image::open(out_png).unwrap().to_rgba8().into_raw())
}

#[test]
fn an_hdr_environment_lights_a_scene_turned_and_scaled() {
    let dir = common::temp_dir("environment", "hdr");
    let (file, env) = (scene(&dir, "scene.toml", ""), dir.join("sky.hdr"));
    hdr(&env);
    let out = dir.join("out.png");
    let (file, env, out) = (file.to_str().unwrap(), env.to_str().unwrap(), out.to_str().unwrap());
    let (table, lit) = render(&["--scene", file, "--environment", env, "--out", out]);
    let row = table.lines().find(|l| l.starts_with("environment")).expect("an environment row");
    assert!(row.contains("64x32 image") && row.contains("prefiltered once at load"), "{row}");
    let (_, turned) = render(&["--scene", file, "--environment", env, "--environment-rotation", "180", "--out", out]);
    let (_, doubled) = render(&["--scene", file, "--environment", env, "--environment-intensity", "2", "--out", out]);
    for (what, other) in [("a turned one", &turned), ("twice as bright", &doubled)] {
        let (worst, pixels) = rgba_difference(&lit, other);
        println!("{what}: {pixels} pixels differ, by up to {worst}/255");
        assert!(pixels > 500 && worst > 10, "{what} gives nearly the same image ({pixels} px, {worst}/255)");
    }
    // The same environment named by the scene file, with its own intensity.
    let named = scene(&dir, "named.toml", "[environment]\nfile = \"sky.hdr\"\nintensity = 2.0\n");
    let (_, from_file) = render(&["--scene", named.to_str().unwrap(), "--out", out]);
    assert_eq!(rgba_difference(&from_file, &doubled), (0, 0), "the file's [environment] is the command line's");
    // Shown behind the scene: pixels of the dark grey background change, no other does.
    let (_, shown) = render(&["--scene", file, "--environment", env, "--background", "environment", "--out", out]);
    let (lit_px, shown_px) = (lit.chunks(4), shown.chunks(4));
    let changed: Vec<bool> = lit_px.clone().zip(shown_px).map(|(a, b)| a != b).collect();
    let grey: Vec<bool> = lit_px.map(|p| p == [5, 5, 5, 255]).collect();
    assert!(changed.iter().filter(|&&c| c).count() > 500, "the background shows the environment");
    assert_eq!(changed, grey, "exactly the background's pixels change");
    // A scene file asks for it with [environment] background = true; --background colour
    // still has the last word.
    let shown_file = scene(&dir, "shown.toml", "[environment]\nfile = \"sky.hdr\"\nbackground = true\n");
    let (_, from_file) = render(&["--scene", shown_file.to_str().unwrap(), "--out", out]);
    assert_eq!(rgba_difference(&from_file, &shown), (0, 0), "the file's background is the command line's");
    let (_, overridden) = render(&["--scene", shown_file.to_str().unwrap(), "--background", "colour", "--out", out]);
    assert_eq!(rgba_difference(&overridden, &lit), (0, 0), "--background colour over the file's");
}

#[test]
fn what_is_not_an_environment_is_refused_in_one_line() {
    let dir = common::temp_dir("environment", "refused");
    let file = scene(&dir, "scene.toml", "");
    let png = dir.join("not.hdr");
    std::fs::write(&png, b"\x89PNG\r\n\x1a\n not really").unwrap();
    let out = dir.join("out.png");
    let (file, out) = (file.to_str().unwrap(), out.to_str().unwrap());
    let run_on = |scene: &str, extra: &[&str]| {
        let mut all = vec!["render", "--scene", scene, "--out", out];
        all.extend(SIZE);
        all.extend(extra);
        manylights(&all)
    };
    let run = |extra: &[&str]| run_on(file, extra);
    assert_one_line_error(&run(&["--environment", dir.join("missing.hdr").to_str().unwrap()]), &["cannot read environment", "missing.hdr"]);
    assert_one_line_error(&run(&["--environment", png.to_str().unwrap()]), &["not an image this reads", "not.hdr"]);
    assert_one_line_error(&run(&["--environment", dir.to_str().unwrap()]), &["cannot read environment"]);
    assert_one_line_error(&run(&["--environment", "sky", "--environment-intensity", "-1"]), &["environment intensity '-1'"]);
    assert_one_line_error(&run(&["--environment", "sky", "--environment-rotation", "nan"]), &["environment rotation 'nan'"]);
    assert_one_line_error(&run(&["--environment", "sky", "--shading", "seed"]), &["--environment", "pbr"]);
    assert_one_line_error(&run(&["--environment", "none", "--environment-intensity", "2"]), &["--environment-intensity"]);
    assert_one_line_error(&run(&["--environment", "none", "--background", "environment"]), &["--background environment"]);
    assert_one_line_error(&run(&["--shading", "blinn-phong", "--background", "environment"]), &["--background environment", "pbr"]);
    let bad = scene(&dir, "bad.toml", "[environment]\nfile = \"missing.exr\"\n");
    assert_one_line_error(&run_on(bad.to_str().unwrap(), &[]), &["[environment]", "missing.exr"]);
    assert!(!Path::new(out).exists(), "nothing written");
}
