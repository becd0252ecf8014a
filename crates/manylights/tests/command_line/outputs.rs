//! Outputs on a full disk: a render, an image sequence and a bench that cannot finish writing
//! fail with one error line and leave the previous files byte-identical, with no partial file
//! beside them. The full disk is a file-size limit (RLIMIT_FSIZE, with SIGXFSZ ignored so that
//! a write past it fails with an error instead of killing the process): what a test may set
//! without privileges, and a write fails the same way as on a full file system. Beside them:
//! outputs that are not regular files, interrupted sequences (and their rerun with `--resume`),
//! shards of a sequence, bad later frames, and an output this user may not write.

use crate::common;

use common::assert_one_line_error;
use std::collections::BTreeMap;
use std::os::unix::fs::MetadataExt;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Bytes a file may grow to in the "full" runs: less than any PNG, CSV or JSON they write.
const FULL_DISK_BYTES: u64 = 48;

fn manylights(args: &[&str], file_size_limit: Option<u64>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_manylights"));
    cmd.args(args);
    if let Some(limit) = file_size_limit {
        // SAFETY: between fork and exec only async-signal-safe calls are made (signal and
        // setrlimit), on plain values.
        unsafe {
            cmd.pre_exec(move || {
                libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
                let rlimit = libc::rlimit { rlim_cur: limit, rlim_max: limit };
                if libc::setrlimit(libc::RLIMIT_FSIZE, &rlimit) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
    }
    cmd.output().expect("run manylights")
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("manylights-outputs-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Every file under `d` (relative name → bytes).
fn files(d: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut all = BTreeMap::new();
    for entry in std::fs::read_dir(d).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            all.extend(files(&path));
        } else {
            all.insert(path.clone(), std::fs::read(&path).unwrap());
        }
    }
    all
}

fn ok(out: &Output) {
    assert!(out.status.success(), "{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
}

const SMALL: [&str; 6] = ["--technique", "forward", "--width", "48", "--height", "32"];

#[test]
fn a_render_into_a_full_disk_keeps_the_previous_image() {
    let d = dir("render");
    let (png, new) = (d.join("image.png"), d.join("new.png"));
    let render = |out: &Path, lights: &str, limit| {
        let mut args = vec!["render", "--validation", "--time", "0", "--lights", lights, "--out", out.to_str().unwrap()];
        args.extend(SMALL);
        manylights(&args, limit)
    };
    ok(&render(&png, "16", None));
    let before = files(&d);
    assert!(image::open(&png).is_ok());
    // A different image that cannot be written: the previous one stays, byte for byte.
    let failed = render(&png, "32", Some(FULL_DISK_BYTES));
    assert_one_line_error(&failed, &["cannot write", "image.png"]);
    // A new path that cannot be written is not made at all.
    assert_one_line_error(&render(&new, "32", Some(FULL_DISK_BYTES)), &["cannot write", "new.png"]);
    assert!(files(&d) == before, "the folder changed: {:?}", files(&d).keys().collect::<Vec<_>>());
}

#[test]
fn a_sequence_into_a_full_disk_keeps_the_previous_frames() {
    let d = dir("sequence");
    let pattern = d.join("frames/##.png");
    let sequence = |limit| {
        let mut args = vec!["render", "--validation", "--frames", "3", "--lights", "16", "--out", pattern.to_str().unwrap()];
        args.extend(SMALL);
        manylights(&args, limit)
    };
    ok(&sequence(None));
    let before = files(&d);
    assert_eq!(before.len(), 3, "{:?}", before.keys());
    assert_one_line_error(&sequence(Some(FULL_DISK_BYTES)), &["cannot write", "00.png"]);
    assert!(files(&d) == before, "the frames changed: {:?}", files(&d).keys().collect::<Vec<_>>());
}

/// A sequence whose later frame cannot be written (here a folder where frame 2 goes) is
/// refused before the first frame: an earlier run's frames stay as they were, not a mix of
/// two runs.
#[test]
fn a_sequence_with_a_bad_later_frame_changes_nothing() {
    let d = dir("bad-later-frame");
    let pattern = d.join("##.png");
    let sequence = |lights: &str| {
        let mut args = vec!["render", "--frames", "3", "--lights", lights, "--out", pattern.to_str().unwrap()];
        args.extend(SMALL);
        manylights(&args, None)
    };
    ok(&sequence("16"));
    std::fs::remove_file(d.join("02.png")).unwrap();
    std::fs::create_dir(d.join("02.png")).unwrap();
    let before = files(&d);
    assert_one_line_error(&sequence("32"), &["cannot write", "02.png", "it is a directory"]);
    assert!(files(&d) == before, "the frames changed: {:?}", files(&d).keys().collect::<Vec<_>>());
}

/// Ctrl+C (SIGINT) while a frame of an image sequence is being written (its temporary file
/// seen beside the finished ones, frames of 1024×1024 so that writing takes a while): the
/// process ends, every frame it finished is a whole PNG, and no temporary file is left.
#[test]
fn an_interrupted_sequence_leaves_whole_frames_and_no_partial_file() {
    let d = dir("interrupted");
    let pattern = d.join("####.png");
    let args = ["render", "--technique", "forward", "--resolution", "1024x1024", "--frames", "200", "--lights", "16"];
    let mut child = Command::new(env!("CARGO_BIN_EXE_manylights"))
        .args(args)
        .args(["--out", pattern.to_str().unwrap()])
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let names = || -> Vec<String> {
        std::fs::read_dir(&d).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).collect()
    };
    let start = std::time::Instant::now();
    loop {
        let now = names();
        if now.iter().any(|n| n.ends_with(".partial")) && now.len() >= 4 {
            break;
        }
        assert!(start.elapsed().as_secs() < 180, "no frame being written after three frames: {now:?}");
        assert!(child.try_wait().unwrap().is_none(), "the sequence ended before it was interrupted");
    }
    // SAFETY: a signal to the child we started, which has not been waited for.
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGINT) }, 0);
    let status = child.wait().unwrap();
    assert!(!status.success(), "interrupted, it still says it succeeded");
    let left = names();
    let partial: Vec<_> = left.iter().filter(|n| n.ends_with(".partial")).collect();
    assert!(partial.is_empty(), "left behind: {partial:?}");
    assert!(left.len() >= 3 && left.len() < 200, "{} frames", left.len());
    for name in &left {
        let frame = image::open(d.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!((frame.width(), frame.height()), (1024, 1024), "{name}");
    }
    // Rerun with --resume (a shard of the first frames, to keep it short): the frames written
    // before the interruption stay as they are (the same file, not written again), the rest
    // of the shard are written, and nothing is left beside them.
    // (Frames are written by several threads: those left need not be the first ones.)
    let written = |n: u32| std::fs::metadata(d.join(format!("{n:04}.png"))).ok().map(|m| (m.ino(), m.modified().unwrap()));
    let last = left.iter().filter_map(|n| n.trim_end_matches(".png").parse::<u32>().ok()).max().unwrap();
    // Shard 0 of 200 / (last + 3): the frames up to at least last + 2.
    let count = 200 / (last + 3);
    let end = 200 / count;
    let before: Vec<_> = (0..end).map(written).collect();
    ok(&manylights(&[&args[..], &["--shard", &format!("0/{count}"), "--resume", "--out", pattern.to_str().unwrap()]].concat(), None));
    for (n, was) in before.iter().enumerate() {
        let now = written(n as u32).unwrap_or_else(|| panic!("frame {n} missing after the rerun"));
        if let Some(was) = was {
            assert_eq!(*was, now, "frame {n} was written again");
        }
    }
    assert!(before.iter().filter(|w| w.is_none()).count() >= 2, "{before:?}");
    assert!(names().iter().all(|n| !n.ends_with(".partial")), "{:?}", names());
}

/// A sequence rendered in shards, and rerun with --resume where frames are missing, gives the
/// frames the whole sequence gives, byte for byte — with the exposure fixed (each frame is its
/// clock's) and automatic (metered from frame to frame: a shard renders the frames before its
/// own without writing them); a rerun with nothing left to write renders nothing.
#[test]
fn shards_and_reruns_write_the_frames_the_whole_sequence_writes() {
    let d = dir("shards");
    let render = |exposure: &str, out: &Path, more: &[&str]| {
        let args = ["render", "--technique", "forward", "--resolution", "96x54", "--frames", "6", "--exposure", exposure];
        let out = manylights(&[&args[..], more, &["--out", out.join("#.png").to_str().unwrap()]].concat(), None);
        ok(&out);
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let frames =
        |folder: &Path| -> Vec<Vec<u8>> { (0..6).map(|i| std::fs::read(folder.join(format!("{i}.png"))).unwrap_or_default()).collect() };
    for exposure in ["0", "auto"] {
        let (whole, parts) = (d.join(format!("whole-{exposure}")), d.join(format!("parts-{exposure}")));
        render(exposure, &whole, &[]);
        let shards: &[u32] = if exposure == "auto" { &[2] } else { &[0, 1, 2] };
        for i in shards {
            let table = render(exposure, &parts, &["--shard", &format!("{i}/3")]);
            assert!(table.contains("2 frames written"), "shard {i}/3: {table}");
            // Where a frame's time goes besides the GPU.
            for part in ["read back", "encoded", "ms and written", "the renderer waited"] {
                assert!(table.lines().any(|l| l.starts_with("sequence") && l.contains(part)), "shard {i}/3: no '{part}': {table}");
            }
        }
        let (a, b) = (frames(&whole), frames(&parts));
        for i in 0..6 {
            if exposure == "0" || i >= 4 {
                assert!(!a[i].is_empty() && a[i] == b[i], "exposure {exposure}: frame {i} of the shards differs");
            }
        }
    }
    let parts = d.join("parts-0");
    for i in [1, 4] {
        std::fs::remove_file(parts.join(format!("{i}.png"))).unwrap();
    }
    let kept = std::fs::metadata(parts.join("2.png")).unwrap().modified().unwrap();
    assert!(render("0", &parts, &["--resume"]).contains("2 frames written"));
    assert_eq!(frames(&d.join("whole-0")), frames(&parts), "the rerun's frames differ");
    assert_eq!(std::fs::metadata(parts.join("2.png")).unwrap().modified().unwrap(), kept, "a written frame was written again");
    assert!(render("0", &parts, &["--resume"]).contains("nothing to render"));
    assert_one_line_error(&manylights(&["render", "--shard", "0/2", "--out", d.join("one.png").to_str().unwrap()], None), &["--shard"]);
    assert_one_line_error(
        &manylights(&["render", "--frames", "4", "--shard", "2/2", "--out", d.join("#.png").to_str().unwrap()], None),
        &["--shard 2/2"],
    );
}

#[test]
fn a_bench_into_a_full_disk_keeps_the_previous_results() {
    let d = dir("bench");
    let bench = |limit| {
        let args = [
            "bench",
            "--validation",
            "--techniques",
            "forward",
            "--lights",
            "64",
            "--resolution",
            "32x32",
            "--frames",
            "2",
            "--warmup",
            "1",
        ];
        manylights(&[&args[..], &["--out", d.to_str().unwrap()]].concat(), limit)
    };
    ok(&bench(None));
    let before = files(&d);
    let names: Vec<_> = before.keys().filter_map(|p| p.file_name()).map(|n| n.to_string_lossy().into_owned()).collect();
    assert!(["results.csv", "results.json", "results.png"].iter().all(|n| names.contains(&n.to_string())), "{names:?}");
    assert_one_line_error(&bench(Some(FULL_DISK_BYTES)), &["cannot write", "results.csv"]);
    assert!(files(&d) == before, "the results changed: {:?}", files(&d).keys().collect::<Vec<_>>());
    // The plot's path taken by a folder: refused before the run, and the table and its JSON
    // stay the earlier run's (the three are replaced together or not at all).
    std::fs::remove_file(d.join("results.png")).unwrap();
    std::fs::create_dir(d.join("results.png")).unwrap();
    let before = files(&d);
    let start = std::time::Instant::now();
    assert_one_line_error(&bench(None), &["cannot write", "results.png", "it is a directory"]);
    assert!(start.elapsed().as_secs() < 10, "refused only after {:?}", start.elapsed());
    assert!(files(&d) == before, "the results changed: {:?}", files(&d).keys().collect::<Vec<_>>());
}

/// Outputs that are not regular files (a pipe would block the writer forever, a device never
/// fills) are refused before any work.
#[test]
fn outputs_that_are_not_regular_files_are_refused_at_once() {
    let d = dir("special");
    let fifo = d.join("pipe.png");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo");
    let device = d.join("null.png");
    std::os::unix::fs::symlink("/dev/null", &device).unwrap();
    for out in [&fifo, &device] {
        let start = std::time::Instant::now();
        let mut args = vec!["render", "--out", out.to_str().unwrap()];
        args.extend(SMALL);
        assert_one_line_error(&manylights(&args, None), &["cannot write", "not a regular file"]);
        assert!(start.elapsed().as_secs() < 5, "{} took {:?}", out.display(), start.elapsed());
    }
    let mut args = vec!["render", "--out", "image.jpg"];
    args.extend(SMALL);
    assert_one_line_error(&manylights(&args, None), &["--out", ".png"]);
}

/// An output this user may not write — a read-only (0444) file in a folder anyone may write to
/// — is refused in one line, not replaced around (a rename needs only the folder's
/// permission): its bytes and mode stay. As root (who may write anything), the run is made as
/// the user `nobody`, the file staying root's.
#[test]
fn an_output_this_user_may_not_write_is_refused_not_replaced() {
    use std::os::unix::fs::PermissionsExt;
    let d = dir("read-only");
    // Anyone may write the folder (no sticky bit: the kernel would let a rename replace the file).
    std::fs::set_permissions(&d, std::fs::Permissions::from_mode(0o777)).unwrap();
    let png = d.join("theirs.png");
    std::fs::write(&png, b"someone else's image").unwrap();
    std::fs::set_permissions(&png, std::fs::Permissions::from_mode(0o444)).unwrap();
    let args = ["render", "--width", "16", "--height", "16", "--out", png.to_str().unwrap()];
    // SAFETY: geteuid has no preconditions.
    let root = unsafe { libc::geteuid() } == 0;
    let out = if root {
        Command::new("runuser").args(["-u", "nobody", "--", env!("CARGO_BIN_EXE_manylights")]).args(args).output().expect("run runuser")
    } else {
        manylights(&args, None)
    };
    assert_one_line_error(&out, &["theirs.png", "read-only to this user", "not replaced"]);
    assert_eq!(std::fs::read(&png).unwrap(), b"someone else's image");
    assert_eq!(std::fs::metadata(&png).unwrap().permissions().mode() & 0o777, 0o444);
    let left: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(left.len(), 1, "{left:?}");
}
