//! Files written so that nothing is lost: an output is made beside its target under a
//! temporary name and renamed over it only once it is complete, so a full disk, a killed
//! process or an encoder error leaves the previous file byte-identical and no partial file.

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why an output could not be written (the path is named in the message).
#[derive(Debug, Error)]
pub enum WriteError {
    #[error("cannot write '{path}': {problem}")]
    Refused { path: PathBuf, problem: String },
    #[error("cannot write '{path}': {source}")]
    Io { path: PathBuf, source: io::Error },
}

impl WriteError {
    fn refused(path: &Path, problem: impl Into<String>) -> WriteError {
        WriteError::Refused { path: path.to_owned(), problem: problem.into() }
    }
}

/// Where `path` is written: the file itself, or where a symbolic link to a file points (the
/// link stays a link). Refuses a directory, anything that is not a regular file (a device, a
/// pipe or a socket would block or never fill) and a folder that does not exist.
pub fn output_target(path: &Path) -> Result<PathBuf, WriteError> {
    let target = match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => match std::fs::canonicalize(path) {
            Ok(resolved) => resolved,
            // A dangling link: what it names is made.
            Err(_) => return Err(WriteError::refused(path, "it is a symbolic link to nothing")),
        },
        _ => path.to_owned(),
    };
    match std::fs::metadata(&target) {
        Ok(meta) if meta.is_dir() => return Err(WriteError::refused(path, "it is a directory")),
        Ok(meta) if !meta.is_file() => {
            return Err(WriteError::refused(path, "it is not a regular file (a device, pipe or socket)"));
        }
        _ => {}
    }
    let folder = parent_folder(&target);
    if !folder.is_dir() {
        return Err(WriteError::refused(path, format!("folder '{}' does not exist", folder.display())));
    }
    Ok(target)
}

/// Fail before any work if `path` could not be replaced: its target is checked and a
/// temporary file is made (and removed) in its folder.
pub fn check_writable(path: &Path) -> Result<(), WriteError> {
    let target = output_target(path)?;
    let (file, temp) = create_temporary(path, &target)?;
    drop(file);
    let _ = std::fs::remove_file(&temp);
    Ok(())
}

/// Write `path` through `write`, which gets a buffered writer on a temporary file beside it;
/// the temporary file replaces `path` only once `write` succeeded and its bytes reached the
/// disk. On any failure the temporary file is removed and `path` is as it was.
pub fn write_replacing<F>(path: &Path, write: F) -> Result<(), WriteError>
where
    F: FnOnce(&mut BufWriter<File>) -> io::Result<()>,
{
    let target = output_target(path)?;
    let (file, temp) = create_temporary(path, &target)?;
    let written = (|| {
        let mut out = BufWriter::new(file);
        write(&mut out)?;
        let file = out.into_inner().map_err(|e| e.into_error())?;
        // Renaming before the bytes are on disk could leave an empty file after a crash.
        file.sync_all()?;
        std::fs::rename(&temp, &target)
    })();
    written.map_err(|source| {
        let _ = std::fs::remove_file(&temp);
        WriteError::Io { path: path.to_owned(), source }
    })
}

/// `write_replacing` with bytes already made.
pub fn write_bytes_replacing(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    write_replacing(path, |out| out.write_all(bytes))
}

/// An RGBA8 image of `width` × `height` as a PNG at `path`, replacing it only once complete.
pub fn write_png(path: &Path, rgba: &[u8], (width, height): (u32, u32)) -> Result<(), WriteError> {
    // (The encoder asserts this; a mistake must be an error, not a panic.)
    if (width as usize).checked_mul(height as usize).and_then(|n| n.checked_mul(4)) != Some(rgba.len()) {
        return Err(WriteError::refused(path, format!("{} bytes are not a {width}×{height} RGBA image", rgba.len())));
    }
    write_replacing(path, |out| {
        image::write_buffer_with_format(out, rgba, width, height, image::ExtendedColorType::Rgba8, image::ImageFormat::Png)
            .map_err(io::Error::other)
    })
}

/// The folder `path` is in ("." for a bare name).
fn parent_folder(path: &Path) -> &Path {
    path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."))
}

/// A new file beside `target` (hidden, named after it and this process, never an existing
/// file); errors name `shown`, the path the user gave.
fn create_temporary(shown: &Path, target: &Path) -> Result<(File, PathBuf), WriteError> {
    let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let folder = parent_folder(target);
    let mut last = None;
    for attempt in 0..16u32 {
        let temp = folder.join(format!(".{name}.{}-{attempt}.partial", std::process::id()));
        match OpenOptions::new().write(true).create_new(true).open(&temp) {
            Ok(file) => return Ok((file, temp)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last = Some(e),
            Err(source) => return Err(WriteError::Io { path: shown.to_owned(), source }),
        }
    }
    Err(WriteError::Io { path: shown.to_owned(), source: last.expect("sixteen attempts made") })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("ml-files-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn entries(d: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        names
    }

    #[test]
    fn a_complete_write_replaces_the_file_and_leaves_nothing_beside_it() {
        let d = dir("complete");
        let path = d.join("out.png");
        std::fs::write(&path, b"old").unwrap();
        write_bytes_replacing(&path, b"new bytes").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new bytes");
        assert_eq!(entries(&d), ["out.png"]);
    }

    #[test]
    fn a_failed_write_keeps_the_previous_file_and_leaves_no_partial_one() {
        let d = dir("failed");
        let path = d.join("out.png");
        std::fs::write(&path, b"previous image").unwrap();
        let result = write_replacing(&path, |out| {
            out.write_all(&[7; 100_000])?;
            Err(io::Error::other("the disk is full"))
        });
        assert!(matches!(result, Err(WriteError::Io { .. })), "{result:?}");
        assert!(result.unwrap_err().to_string().contains("the disk is full"));
        assert_eq!(std::fs::read(&path).unwrap(), b"previous image");
        assert_eq!(entries(&d), ["out.png"]);
        // A new path that fails is not made at all.
        let new = d.join("new.png");
        assert!(write_replacing(&new, |_| Err(io::Error::other("no"))).is_err());
        assert_eq!(entries(&d), ["out.png"]);
    }

    #[test]
    fn directories_devices_pipes_and_missing_folders_are_refused() {
        let d = dir("refused");
        assert!(output_target(&d).unwrap_err().to_string().contains("directory"));
        assert!(output_target(Path::new("/dev/null")).unwrap_err().to_string().contains("not a regular file"));
        assert!(output_target(&d.join("no/such/out.png")).unwrap_err().to_string().contains("does not exist"));
        assert!(check_writable(&d.join("fine.png")).is_ok());
        assert_eq!(entries(&d), Vec::<String>::new());
    }

    #[test]
    fn a_png_decodes_to_what_was_written() {
        let d = dir("png");
        let path = d.join("image.png");
        let rgba: Vec<u8> = (0..4 * 3 * 2).map(|i| i as u8 * 9).collect();
        write_png(&path, &rgba, (3, 2)).unwrap();
        let back = image::open(&path).unwrap().to_rgba8();
        assert_eq!((back.width(), back.height(), back.into_raw()), (3, 2, rgba));
        // A size that disagrees with the pixels fails and leaves nothing.
        assert!(write_png(&d.join("bad.png"), &[0; 5], (3, 2)).is_err());
        assert_eq!(entries(&d), ["image.png"]);
    }

    #[cfg(unix)]
    #[test]
    fn a_link_to_a_file_replaces_the_file_and_stays_a_link() {
        let d = dir("link");
        let (file, link) = (d.join("real.png"), d.join("link.png"));
        std::fs::write(&file, b"old").unwrap();
        std::os::unix::fs::symlink(&file, &link).unwrap();
        write_bytes_replacing(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(&file).unwrap(), b"new");
    }
}
