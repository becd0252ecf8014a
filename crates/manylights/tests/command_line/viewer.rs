//! `manylights view` under a virtual X server (Xvfb, installed by scripts/setup.sh) on
//! lavapipe, with validation and synchronization validation on: a scripted session — frames, a
//! technique switch, a new light count, 20 resizes, minimise/restore, screenshots, quit — runs
//! without a message, and its screenshot equals `manylights render` of the same settings.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("manylights-viewer-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_manylights")
}

/// `manylights view ARGS` in a fresh virtual X server (xvfb-run picks a free display).
fn view_under_xvfb(args: &[&str]) -> Output {
    let found = Command::new("xvfb-run").arg("--help").output();
    assert!(found.is_ok(), "xvfb-run is missing: run scripts/setup.sh (it installs xvfb and xauth)");
    Command::new("xvfb-run").args(["-a", "-s", "-screen 0 1280x800x24", bin(), "view"]).args(args).output().expect("run xvfb-run")
}

fn rgba(path: &Path) -> (u32, u32, Vec<u8>) {
    let image = image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba8();
    (image.width(), image.height(), image.into_raw())
}

/// The session of the first acceptance point, then its second: the screenshot (the
/// rendered image, no overlay) against `render` with the same technique, lights, size and
/// clock.
#[test]
fn a_scripted_session_is_validation_clean_and_its_screenshot_equals_render() {
    let d = dir();
    let (shot, window_shot, rendered) = (d.join("shot.png"), d.join("window.png"), d.join("render.png"));
    let mut script =
        vec!["frames 3".to_owned(), "technique clustered-cpu".into(), "frames 2".into(), "lights 500".into(), "frames 2".into()];
    script.extend(["technique deferred-compute".to_owned(), "frames 2".into()]);
    for i in 0..20 {
        script.push(format!("resize {} {}", 240 + 16 * i, 320 - 8 * i));
        script.push("frames 2".into());
    }
    script.extend(["resize 320 180".to_owned(), "frames 4".into(), "minimize".into(), "frames 5".into(), "restore".into()]);
    script.extend(["frames 5".to_owned(), "technique deferred".into(), "frames 3".into()]);
    script.push(format!("screenshot {}", shot.display()));
    script.push(format!("window-shot {}", window_shot.display()));
    // The README's picture (docs/viewer.png is a copy of it): the overlay at a readable size,
    // anti-aliased (lavapipe's most samples; auto leaves a CPU driver without).
    let readme = Path::new(env!("CARGO_TARGET_TMPDIR")).join("viewer-window.png");
    script.extend([
        "resize 960 540".to_owned(),
        "aa 4".into(),
        "frames 3".into(),
        format!("window-shot {}", readme.display()),
        "quit".into(),
    ]);
    let script_file = d.join("session.txt");
    std::fs::write(&script_file, script.join("\n")).unwrap();
    let common = ["--width", "320", "--height", "180", "--time", "0"];
    let mut args = vec!["--validation", "--script", script_file.to_str().unwrap()];
    args.extend(common);
    let out = view_under_xvfb(&args);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "the session failed: {stdout}{stderr}");
    assert!(!stderr.contains("VALIDATION") && !stderr.contains("panicked"), "{stderr}");
    // What it did: every resize reached the renderer as new targets, not a new renderer.
    let summary = stdout.lines().find(|l| l.starts_with("view: ")).unwrap_or_else(|| panic!("no summary: {stdout}"));
    let numbers: Vec<u32> = summary.split(|c: char| !c.is_ascii_digit()).filter_map(|w| w.parse().ok()).collect();
    let [frames, swapchains, resizes, changes_in_place, renderers, _paused] = numbers[..] else { panic!("{summary}") };
    // Renderers: the first, one per technique switch and one for the samples; the light count
    // changes in place.
    assert!(frames >= 70 && swapchains >= 22 && resizes >= 21 && changes_in_place == 1 && renderers == 5, "{summary}");

    let render = [&["--technique", "deferred", "--lights", "500"][..], &common].concat();
    assert_render_equals(&shot, &render, &rendered);
    let a = rgba(&shot);
    // The window as presented: the same image under the overlay, whose panel sits top left,
    // folded to its title bar (and its shadow) in a window this small (open, it would cover
    // half of it).
    let w = rgba(&window_shot);
    assert_eq!((w.0, w.1), (320, 180));
    let differ = |i: usize| w.2[i..i + 3].iter().zip(&a.2[i..i + 3]).any(|(p, q)| p.abs_diff(*q) > 1);
    let overlaid = |rows: std::ops::Range<u32>| {
        rows.flat_map(|y| (0..320u32).map(move |x| ((y * 320 + x) * 4) as usize)).filter(|&i| differ(i)).count()
    };
    let (title, below) = (overlaid(0..40), overlaid(64..180));
    assert!(title > 2000 && below == 0, "the overlay is not folded to its title bar: {title} pixels differ in the top rows, {below} below");
    // At 960×540 it opens: its panel (egui's window fill, grey 27) over most of its box.
    let r = rgba(&readme);
    assert_eq!((r.0, r.1), (960, 540));
    let panel = (40..440u32)
        .flat_map(|y| (8..340u32).map(move |x| ((y * 960 + x) * 4) as usize))
        .filter(|&i| r.2[i..i + 3] == [27, 27, 27])
        .count();
    assert!(panel > 332 * 400 / 2, "the overlay is not open at 960x540 ({panel} panel pixels)");
}

/// A script with a mistake is refused before a window opens: one error line naming the line.
#[test]
fn a_broken_script_is_one_error_line() {
    let d = dir();
    let file = d.join("broken.txt");
    std::fs::write(&file, "frames 2\nteleport 3\n").unwrap();
    let out = Command::new(bin()).args(["view", "--script", file.to_str().unwrap()]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.lines().count() == 1 && stderr.contains("line 2") && stderr.contains("teleport"), "{stderr}");
    // A script that never ends (a device) or never comes (a pipe no one writes to): refused
    // before it is read, at once.
    let pipe = d.join("script.fifo");
    assert!(Command::new("mkfifo").arg(&pipe).status().unwrap().success());
    for never in [Path::new("/dev/zero"), &pipe] {
        let start = std::time::Instant::now();
        let out = Command::new(bin()).args(["view", "--script", never.to_str().unwrap()]).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(stderr.lines().count() == 1 && stderr.contains("not a regular file"), "{stderr}");
        assert!(start.elapsed().as_secs() < 5, "{:?}", start.elapsed());
    }
}

/// No window system: one error line saying what to do, not a panic, before any GPU work (with
/// auto's technique, and with the visibility technique's raster probe, whose renders would
/// print their own lines first).
#[test]
fn without_a_display_view_is_one_error_line() {
    for args in [&["view"][..], &["view", "--technique", "visibility", "--raster", "auto"]] {
        let out = Command::new(bin())
            .args(args)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .env_remove("WAYLAND_SOCKET")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(stderr.lines().count() == 1 && stderr.contains("cannot open a window") && stderr.contains("xvfb-run"), "{stderr}");
    }
}

/// The visibility technique with the compute raster in the window: through a resize (new
/// targets, its 64-bit buffer among them) validation stays silent and the screenshot equals
/// `render`'s image.
#[test]
fn the_compute_raster_views_what_it_renders() {
    let common =
        ["--technique", "visibility", "--raster", "compute", "--scene", "bench", "--objects", "30", "--lights", "300", "--time", "0"];
    resized_session_matches_render("compute-raster", &common, (3, 1));
}

/// Auto exposure in the window: the viewer starts at the exposure `render --exposure auto`
/// settles on (this scene's: -2.7 EV), not easing in from 0 EV — five frames and a resize in,
/// the screenshot shows render's image within 2/255 (measured: 1), where easing would still
/// be far from it — and the meter's pass through a resize (its sums made again for the new
/// size) stays silent. The technique is named: `auto` picks from a timing probe, which a
/// loaded machine can tip, and two techniques' edge pixels differ by a few levels.
#[test]
fn auto_exposure_starts_where_render_settles() {
    let common = ["--technique", "deferred-clustered", "--shading", "blinn-phong", "--exposure", "auto", "--time", "0"];
    resized_session_matches_render("auto-exposure", &common, (3, 2));
}

/// An environment loaded in the viewer and shown behind the scene (the panel's Load field and
/// Background combo, scripted) gives the image `render --environment sky --background
/// environment` gives.
#[test]
fn an_environment_loaded_live_shows_as_render_shows_it() {
    let common = ["--technique", "visibility", "--shading", "pbr", "--aa", "off", "--time", "0"];
    let session = (&["environment sky", "background environment"][..], &["--environment", "sky", "--background", "environment"][..]);
    session_matches_render("environment", &common, session, (2, 1));
}

/// A validated viewer session with `common` arguments at 160×96: two frames, a resize to
/// 200×120, `frames` frames, a screenshot; it ends cleanly and its screenshot is within
/// `tolerance`/255 of `render` with the same arguments at 200×120.
fn resized_session_matches_render(name: &str, common: &[&str], frames_tolerance: (u32, u8)) {
    session_matches_render(name, common, (&[], &[]), frames_tolerance);
}

/// `resized_session_matches_render` with `steps` run after the first two frames, and
/// `render_args` given to render besides `common` (what those steps change).
fn session_matches_render(name: &str, common: &[&str], (steps, render_args): (&[&str], &[&str]), (frames, tolerance): (u32, u8)) {
    let d = dir();
    let (shot, rendered) = (d.join(format!("{name}-shot.png")), d.join(format!("{name}-render.png")));
    let mut script = vec!["frames 2".to_owned()];
    script.extend(steps.iter().map(|s| s.to_string()));
    script.extend(["resize 200 120".into(), format!("frames {frames}"), format!("screenshot {}", shot.display()), "quit".into()]);
    let script_file = d.join(format!("{name}.txt"));
    std::fs::write(&script_file, script.join("\n")).unwrap();
    let mut args = vec!["--validation", "--script", script_file.to_str().unwrap(), "--width", "160", "--height", "96"];
    args.extend(common);
    let out = view_under_xvfb(&args);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "the session failed: {stdout}{stderr}");
    assert!(!stderr.contains("VALIDATION") && !stderr.contains("panicked"), "{stderr}");
    let worst =
        render_difference(&shot, &[&["--validation", "--width", "200", "--height", "120"][..], common, render_args].concat(), &rendered);
    println!("{name}: the viewer's screenshot and render differ by at most {worst}/255");
    assert!(worst <= tolerance, "{name}: the viewer's screenshot differs from render by {worst}/255");
}

/// `render ARGS --out rendered` succeeds and its image equals the viewer's screenshot `shot`
/// within 1/255.
fn assert_render_equals(shot: &Path, args: &[&str], rendered: &Path) {
    let worst = render_difference(shot, args, rendered);
    assert!(worst <= 1, "the viewer's screenshot differs from render by {worst}/255");
}

/// Run `render ARGS --out rendered` (it must succeed); the largest channel difference between
/// its image and the viewer's screenshot `shot` (of the same size).
fn render_difference(shot: &Path, args: &[&str], rendered: &Path) -> u8 {
    let r = Command::new(bin()).arg("render").args(args).args(["--out", rendered.to_str().unwrap()]).output().unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let (a, b) = (rgba(shot), rgba(rendered));
    assert_eq!((a.0, a.1), (b.0, b.1));
    a.2.iter().zip(&b.2).map(|(x, y)| x.abs_diff(*y)).max().unwrap()
}
