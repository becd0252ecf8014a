//! What a new user meets with their own scene (docs/usage.md): `--camera` frames a scene as
//! a scene file's camera does, a file without lights gets the default rig and says so, an
//! image sequence writes every frame (its last the `--frames N` image), and bad values of the
//! new options get one error line.

use crate::common;

use common::{assert_one_line_error, manylights};
use std::path::{Path, PathBuf};
use std::process::Output;

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("first-hour", name)
}

fn ok(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{}{stderr}", String::from_utf8_lossy(&out.stdout));
    stderr
}

fn pixels(path: &Path) -> image::RgbaImage {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba8()
}

const SIZE: [&str; 4] = ["--width", "96", "--height", "64"];

/// A scene file of a torus knot and a floor, its lights the default rig; `camera` its
/// [camera] section.
fn scene_file(dir: &Path, name: &str, camera: &str) -> PathBuf {
    let path = dir.join(name);
    let text = format!(
        "{camera}\n[shading]\nmodel = \"pbr\"\n\n[[objects]]\nmesh = \"torusknot\"\nposition = [0.0, 1.0, 0.0]\n\n\
         [[objects]]\nmesh = \"plane\"\nscale = 4.0\nmaterial = {{ name = \"white\" }}\n"
    );
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn camera_option_gives_the_scene_files_camera_image() {
    let dir = temp_dir("camera");
    let with_camera = scene_file(&dir, "with.toml", "[camera]\nposition = [3.0, 4.0, 5.0]\ntarget = [0.0, 0.5, 0.0]\nfov_y_deg = 45.0\n");
    let without = scene_file(&dir, "without.toml", "");
    let (a, b, framed) = (dir.join("file.png"), dir.join("option.png"), dir.join("framed.png"));
    // One technique for all three (auto's pick may differ from run to run, by 1/255 at most).
    let render = |scene: &Path, out: &Path, extra: &[&str]| {
        let mut args =
            vec!["render", "--validation", "--technique", "forward", "--scene", scene.to_str().unwrap(), "--out", out.to_str().unwrap()];
        args.extend(SIZE);
        args.extend(extra);
        ok(&manylights(&args))
    };
    render(&with_camera, &a, &[]);
    let stderr = render(&without, &b, &["--camera", "3,4,5:0,0.5,0:45"]);
    // Neither file has lights: both get the rig, and say so.
    assert!(stderr.contains("the scene has no lights: added 64 point lights (grid layout"), "{stderr}");
    render(&without, &framed, &[]);
    let (a, b, framed) = (pixels(&a), pixels(&b), pixels(&framed));
    assert!(a == b, "--camera and the scene file's camera differ");
    assert!(a != framed, "the framing camera gave the same image: the camera was not used");
}

#[test]
fn an_image_sequence_has_every_frame_and_ends_with_the_frames_image() {
    // Also under auto exposure, whose render settles its last frame before returning it.
    for exposure in ["0", "auto"] {
        let dir = temp_dir(&format!("sequence-{exposure}"));
        let pattern = dir.join("frames").join("##.png");
        std::fs::create_dir_all(dir.join("frames")).unwrap();
        let last = dir.join("last.png");
        // Technique clustered-gpu: its frames are the ones that can be rendered again.
        let render = |out: &Path| {
            let mut args = vec!["render", "--validation", "--technique", "clustered-gpu", "--frames", "5", "--out", out.to_str().unwrap()];
            args.extend(SIZE);
            args.extend(["--exposure", exposure]);
            ok(&manylights(&args))
        };
        render(&pattern);
        render(&last);
        let mut files: Vec<String> =
            std::fs::read_dir(dir.join("frames")).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        files.sort();
        assert_eq!(files, ["00.png", "01.png", "02.png", "03.png", "04.png"]);
        let frames: Vec<_> = files.iter().map(|f| pixels(&dir.join("frames").join(f))).collect();
        assert!(frames[4] == pixels(&last), "exposure {exposure}: the sequence's last frame differs from the --frames 5 image");
        // The lights move: the frames are not one image written five times.
        assert!(frames[0] != frames[4]);
    }
}

/// Mean luma (Rec. 709 weights on the 8-bit values, 0…1) over the whole image.
fn mean_luma(image: &image::RgbaImage) -> f64 {
    let sum: f64 = image.pixels().map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64).sum();
    sum / 255.0 / (image.width() * image.height()) as f64
}

/// An image sequence into folders that do not exist yet: they are made, and under auto
/// exposure (a scene file's default) the first frame is exposed like the last, not dark.
#[test]
fn a_sequence_makes_its_folder_and_starts_exposed() {
    let dir = temp_dir("new-folder");
    let file = scene_file(&dir, "knot.toml", "");
    let folder = dir.join("renders").join("knot");
    assert!(!folder.exists());
    let pattern = folder.join("###.png");
    let mut args = vec!["render", "--validation", "--scene", file.to_str().unwrap(), "--frames", "6", "--out", pattern.to_str().unwrap()];
    args.extend(SIZE);
    ok(&manylights(&args));
    let first = pixels(&folder.join("000.png"));
    let last = pixels(&folder.join("005.png"));
    let (a, b) = (mean_luma(&first), mean_luma(&last));
    println!("mean luma: first frame {a:.4}, last {b:.4}");
    assert!((a / b - 1.0).abs() <= 0.02, "the first frame's mean luma {a:.4} is not within 2 % of the last's {b:.4}");
}

#[test]
fn bad_cameras_exposures_frames_and_patterns_are_refused() {
    let dir = temp_dir("bad");
    let out = dir.join("never.png");
    let p = out.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["render", "--out", p];
        args.extend(extra);
        manylights(&args)
    };
    assert_one_line_error(&run(&["--camera", "1,2:3,4,5"]), &["--camera", "EYE_X,EYE_Y,EYE_Z:TARGET_X,TARGET_Y,TARGET_Z"]);
    assert_one_line_error(&run(&["--camera", "1,2,3:1,2,3"]), &["--camera", "looks nowhere"]);
    assert_one_line_error(&run(&["--camera", "1,2,3:4,5,6:200"]), &["--camera", "field of view"]);
    assert_one_line_error(&run(&["--camera", "-1,2,3:-1,-5,3"]), &["--camera", "straight up or down"]);
    assert_one_line_error(&run(&["--exposure", "100"]), &["--exposure", "-20 to 20"]);
    assert_one_line_error(&run(&["--exposure", "bright"]), &["--exposure", "'bright'"]);
    assert_one_line_error(&run(&["--frames", "1000000"]), &["--frames 1000000", "100000"]);
    assert_one_line_error(&run(&["--light-layout", "spiral"]), &["spiral", "grid, random, surface"]);
    let bench = manylights(&["bench", "--camera", "1,2,3", "--out", dir.join("bench").to_str().unwrap()]);
    assert_one_line_error(&bench, &["--camera", "EYE_X,EYE_Y,EYE_Z"]);
    assert_one_line_error(&run(&["--show-lights", "--omni-shadow", "layered"]), &["--show-lights", "--omni-shadow"]);
    assert_one_line_error(&run(&["--show-lights", "--lights", "70000"]), &["--show-lights", "70000 lights", "65536"]);
    let bad_pattern = dir.join("a#b#.png");
    assert_one_line_error(&manylights(&["render", "--frames", "2", "--out", bad_pattern.to_str().unwrap()]), &["one run of #"]);
    assert!(!out.exists());
}

#[test]
fn exposure_scales_the_lit_image() {
    let dir = temp_dir("exposure");
    let (plain, darker) = (dir.join("plain.png"), dir.join("darker.png"));
    for (out, ev) in [(&plain, "0"), (&darker, "-2")] {
        // A technique named: what auto picks is its own tests' subject (and costs probes).
        let mut args =
            vec!["render", "--validation", "--technique", "deferred-clustered", "--exposure", ev, "--out", out.to_str().unwrap()];
        args.extend(SIZE);
        ok(&manylights(&args));
    }
    let mean = |p: &Path| pixels(p).pixels().map(|px| px[0] as f64 + px[1] as f64 + px[2] as f64).sum::<f64>();
    let (a, b) = (mean(&plain), mean(&darker));
    assert!(b < a * 0.75, "EV -2 should darken the image: {b} against {a}");
}

/// A scene file is exposed automatically unless `--exposure` says otherwise (or it is a pbr
/// scene without lights, which the default rig and sky light at EV 0); the built-in
/// scenes are not (their images stay), and `--exposure auto` meters them too. The table says
/// which EV auto exposure settled on.
#[test]
fn files_are_exposed_automatically_and_built_in_scenes_on_request() {
    let dir = temp_dir("auto-exposure");
    let scene = scene_file(&dir, "scene.toml", "");
    let out = dir.join("out.png");
    let render = |extra: &[&str]| {
        let mut args = vec!["render", "--validation", "--technique", "deferred-clustered", "--out", out.to_str().unwrap()];
        args.extend(SIZE);
        args.extend(extra);
        let run = manylights(&args);
        ok(&run);
        String::from_utf8_lossy(&run.stdout).into_owned()
    };
    let metered = |table: &str| table.lines().any(|l| l.starts_with("exposure") && l.contains("auto:") && l.contains("EV"));
    assert!(metered(&render(&["--scene", scene.to_str().unwrap(), "--environment", "none"])), "a scene file is metered by default");
    // Unless it has no lights of its own and the default rig and sky light it (the pbr model):
    // then it is shown at EV 0, as a glTF viewer shows it.
    let pbr = ["--scene", scene.to_str().unwrap(), "--shading", "pbr"];
    assert!(!metered(&render(&pbr)), "the default sky and rig are shown at EV 0");
    assert!(!metered(&render(&["--scene", scene.to_str().unwrap(), "--exposure", "0"])), "--exposure 0 fixes it");
    assert!(!metered(&render(&[])), "the seed scene keeps EV 0");
    assert!(metered(&render(&["--exposure", "auto", "--shading", "blinn-phong"])), "--exposure auto meters the seed scene");
}

/// A white matte model without lights: the default rig's near-white lights show it white
/// (mean saturation of its pixels at most 0.15; the seed's palette, asked for, tints it), and
/// the table's `camera` row, given back as `--camera`, shows the same image.
#[test]
fn a_white_model_without_lights_renders_white_and_its_camera_row_is_ready_to_use() {
    use ml_cpu::gltf_writer::{quad, GltfWriter, PrimitiveData};
    let dir = temp_dir("white");
    let model = dir.join("white.glb");
    let mut w = GltfWriter::new();
    let white = w.material([1.0, 1.0, 1.0, 1.0], 0.0, 1.0);
    let mesh = w.mesh(&[PrimitiveData { material: Some(white), ..quad() }]);
    w.node(serde_json::json!({ "mesh": mesh }), true);
    std::fs::write(&model, w.to_glb()).unwrap();
    let render = |out: &Path, extra: &[&str]| {
        let mut args =
            vec!["render", "--validation", "--technique", "forward", "--scene", model.to_str().unwrap(), "--out", out.to_str().unwrap()];
        args.extend(SIZE);
        args.extend(extra);
        let out = manylights(&args);
        ok(&out);
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    // Mean saturation of the pixels the model covers (brighter than the background).
    let saturation = |path: &Path| {
        let (mut sum, mut n) = (0.0, 0);
        for p in pixels(path).pixels() {
            let (max, min) = (p[0].max(p[1]).max(p[2]) as f32, p[0].min(p[1]).min(p[2]) as f32);
            if max > 40.0 {
                sum += (max - min) / max;
                n += 1;
            }
        }
        assert!(n > 500, "{}: the model covers only {n} pixels", path.display());
        sum / n as f32
    };
    let (plain, palette, again) = (dir.join("plain.png"), dir.join("palette.png"), dir.join("again.png"));
    let table = render(&plain, &[]);
    // The palette's lights alone (the default sky would light it too).
    render(&palette, &["--light-colors", "palette", "--environment", "none"]);
    let (white, tinted) = (saturation(&plain), saturation(&palette));
    println!("mean saturation: {white:.3} with the default rig, {tinted:.3} with the palette");
    assert!(white <= 0.15, "the default rig tints a white model: mean saturation {white}");
    assert!(tinted > 0.15, "the palette does not tint: {tinted}");
    let camera = table.lines().find_map(|l| l.strip_prefix("camera")).map(str::trim).expect("a camera row");
    let spec = camera.strip_prefix("--camera ").unwrap_or_else(|| panic!("not an option: {camera}"));
    render(&again, &["--camera", spec]);
    let (a, b) = (pixels(&plain), pixels(&again));
    let worst = a.pixels().zip(b.pixels()).map(|(p, q)| (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap()).max().unwrap();
    assert!(worst <= 1, "--camera {spec} shows another image (by {worst}/255)");
}

/// A model with a texture file missing, a KTX2 texture and a skin renders, each named in a
/// warning (a viewer shows such a model with stand-ins).
#[test]
fn a_model_with_missing_and_ktx_textures_and_a_skin_renders_and_says_what_is_left_out() {
    use ml_cpu::gltf_writer::{quad, GltfWriter, PrimitiveData};
    let dir = temp_dir("left-out");
    let mut w = GltfWriter::new();
    let ktx = w.texture(b"\xABKTX 20\xBB\r\n\x1A\n0000".to_vec(), "image/ktx2");
    let missing = w.texture(vec![0; 4], "image/png");
    w.json["images"][missing] = serde_json::json!({ "uri": "textures/gone.png" });
    let m = w.textured_material(Some(ktx), Some(missing));
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(serde_json::json!({ "mesh": mesh, "skin": 0 }), true);
    w.json["skins"] = serde_json::json!([{ "joints": [0] }]);
    let model = dir.join("left-out.gltf");
    std::fs::write(&model, w.to_gltf()).unwrap();
    let out = dir.join("left-out.png");
    let mut args =
        vec!["render", "--validation", "--technique", "forward", "--scene", model.to_str().unwrap(), "--out", out.to_str().unwrap()];
    args.extend(SIZE);
    let stderr = ok(&manylights(&args));
    for said in [
        "the base colour texture (image 0) is left out: it is a KTX2 image",
        "the normal texture (image 1) is left out: its file 'textures/gone.png' does not exist",
        "1 skin(s) are not applied",
    ] {
        assert!(stderr.contains(said), "'{said}' not in:\n{stderr}");
    }
    assert!(pixels(&out).pixels().any(|p| p[0].max(p[1]).max(p[2]) > 40), "nothing drawn");
}

/// The seed scene at 100,000 lights: its radius follows the count beyond its own 64, so the
/// lights per cluster stay few (at the seed's radius 15 every cluster held thousands and the
/// light lists outgrew the device) and the render finishes like any other.
#[test]
fn the_seed_scene_takes_a_hundred_thousand_lights() {
    let out = temp_dir("seed-100k").join("seed.png");
    let args = ["render", "--validation", "--technique", "deferred-clustered", "--lights", "100k", "--width", "160", "--height", "90"];
    let run = manylights(&[&args[..], &["--out", out.to_str().unwrap()]].concat());
    ok(&run);
    let stdout = String::from_utf8_lossy(&run.stdout);
    let mean: f32 = stdout
        .lines()
        .find_map(|l| l.strip_prefix("lights/cluster"))
        .and_then(|l| l.trim().strip_prefix("mean "))
        .and_then(|l| l.split(',').next())
        .and_then(|m| m.parse().ok())
        .unwrap_or_else(|| panic!("no lights/cluster row:\n{stdout}"));
    let lights = stdout.lines().find_map(|l| l.strip_prefix("lights ")).map(str::trim);
    assert_eq!(lights, Some("100000"), "{stdout}");
    assert!(mean < 64.0, "{mean} lights a cluster on average");
}
