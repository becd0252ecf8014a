//! Where `render` writes: one PNG, or an image sequence of them, each replaced only once it
//! is complete (ml_cpu::files::write_png), after the path was checked before any GPU work.

use anyhow::{bail, Context as _, Result};
use ml_cpu::files;
use std::path::{Path, PathBuf};

/// An image sequence's pattern: the name before and after its run of #, and the run's length.
pub type SequencePattern = (String, String, usize);

/// `--out`, checked before any work: a PNG's name, with a run of # for an image sequence (the
/// name before and after it and its length; None without a #). An error where # stands
/// elsewhere than in one run of the file name.
pub fn sequence_pattern(out: &Path) -> Result<Option<SequencePattern>> {
    if !out.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        bail!("--out '{}': the image is written as PNG, so its name must end in .png", out.display());
    }
    let text = out.to_string_lossy();
    let Some(first) = text.find('#') else { return Ok(None) };
    let run = text[first..].find(|c| c != '#').map_or(text.len() - first, |n| n);
    let (before, after) = (&text[..first], &text[first + run..]);
    if after.contains('#') || after.contains(std::path::MAIN_SEPARATOR) {
        bail!("--out '{text}': an image sequence's name has one run of # in the file name (e.g. frames/####.png)");
    }
    Ok(Some((before.to_owned(), after.to_owned(), run)))
}

/// Frame `i`'s file of a sequence pattern.
pub fn sequence_path((before, after, digits): &SequencePattern, i: u32) -> PathBuf {
    PathBuf::from(format!("{before}{i:0digits$}{after}"))
}

/// Fail before rendering if the image (or any of a sequence's `frames` frames) could not be
/// written: nothing is computed for nothing, and a sequence never stops after replacing some
/// of an earlier run's frames. A sequence's folder is made for it (a single image's must
/// exist).
pub fn prepare(out: &Path, sequence: Option<&SequencePattern>, frames: u32) -> Result<()> {
    let Some(pattern) = sequence else { return Ok(files::check_writable(out)?) };
    let first = sequence_path(pattern, 0);
    if let Some(folder) = first.parent().filter(|p| !p.as_os_str().is_empty() && !p.is_dir()) {
        std::fs::create_dir_all(folder).with_context(|| format!("cannot make folder '{}'", folder.display()))?;
    }
    for i in 0..frames.max(1) {
        files::check_writable(&sequence_path(pattern, i))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequence_patterns_number_frames_in_their_run_of_hashes() {
        let p = sequence_pattern(Path::new("frames/####.png")).unwrap().unwrap();
        assert_eq!(sequence_path(&p, 7), PathBuf::from("frames/0007.png"));
        assert_eq!(sequence_path(&p, 12345), PathBuf::from("frames/12345.png"));
        let p = sequence_pattern(Path::new("turn-#.png")).unwrap().unwrap();
        assert_eq!(sequence_path(&p, 3), PathBuf::from("turn-3.png"));
        assert_eq!(sequence_pattern(Path::new("plain.png")).unwrap(), None);
        for bad in ["a#b#.png", "frames#/#.png", "##x##.png", "##.jpg", "out"] {
            assert!(sequence_pattern(Path::new(bad)).is_err(), "{bad}");
        }
    }
}
