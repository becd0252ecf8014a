//! What the command-line tests share.

// Each test file compiles this module on its own and uses a part of it.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// Run the binary with `args`.
pub fn manylights(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_manylights")).args(args).output().expect("run manylights")
}

/// A folder of the system's temporary one for test `name` of `suite` (made if missing).
pub fn temp_dir(suite: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("manylights-{suite}-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Fails unless the run failed with exactly one `error:` line mentioning every `needle`.
pub fn assert_one_line_error(out: &Output, needles: &[&str]) {
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

/// Largest per-channel difference between two RGBA byte arrays of one size, and how many
/// pixels differ at all.
pub fn rgba_difference(a: &[u8], b: &[u8]) -> (u8, usize) {
    assert_eq!(a.len(), b.len(), "images of one size");
    a.chunks_exact(4).zip(b.chunks_exact(4)).fold((0, 0), |(worst, pixels), (pa, pb)| {
        let d = pa.iter().zip(pb).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(0);
        (d.max(worst), pixels + usize::from(d > 0))
    })
}
