//! Files written so that nothing is lost: an output is made beside its target under a
//! temporary name and renamed over it only once it is complete, so a full disk, an
//! interrupted process (the binary removes the temporary files on a signal:
//! `remove_temporaries`) or an encoder error leaves the previous file byte-identical and no
//! partial file; the replacement keeps the replaced file's mode.
//! And files read so that a hostile one cannot hang or exhaust us: regular files only, never
//! more bytes than a cap (`read_regular`).

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The temporary files this process is writing: removed by `remove_temporaries` when a signal
/// ends the process (the binary's SIGINT/SIGTERM handler), so an interrupted write leaves
/// nothing beside its output.
static TEMPORARIES: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Remove every temporary file this process has open for writing (none is renamed after it:
/// call it only on the way out).
pub fn remove_temporaries() {
    let temps = TEMPORARIES.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    for t in temps.iter() {
        let _ = std::fs::remove_file(t);
    }
}

fn forget_temporary(temp: &Path) {
    let mut temps = TEMPORARIES.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    temps.retain(|t| t != temp);
}

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
    forget_temporary(&temp);
    Ok(())
}

/// Write `path` through `write`, which gets a buffered writer on a temporary file beside it;
/// the temporary file replaces `path` only once `write` succeeded and its bytes reached the
/// disk. On any failure the temporary file is removed and `path` is as it was.
pub fn write_replacing<F>(path: &Path, write: F) -> Result<(), WriteError>
where
    F: FnOnce(&mut BufWriter<File>) -> io::Result<()>,
{
    let mut pending = Pending::begin(path)?;
    let written = pending.fill(write).and_then(|()| std::fs::rename(&pending.temp, &pending.target));
    pending.end(written.is_ok());
    written.map_err(|source| WriteError::Io { path: path.to_owned(), source })
}

/// An output being written: where it goes, its temporary file beside it, and the mode of the
/// file it replaces.
struct Pending {
    target: PathBuf,
    temp: PathBuf,
    file: Option<File>,
    previous: Option<std::fs::Metadata>,
}

impl Pending {
    /// `path`'s target checked and its temporary file made (registered for removal on a
    /// signal).
    fn begin(path: &Path) -> Result<Pending, WriteError> {
        let target = output_target(path)?;
        let previous = std::fs::metadata(&target).ok();
        #[cfg(unix)]
        if let Some(links) = previous.as_ref().map(std::os::unix::fs::MetadataExt::nlink).filter(|&n| n > 1) {
            // A rename gives the path a new file: the other names keep the old bytes.
            eprintln!(
                "warning: '{}' has {} other hard link(s): it is replaced by a new file, which they do not share",
                path.display(),
                links - 1
            );
        }
        let (file, temp) = create_temporary(path, &target)?;
        Ok(Pending { target, temp, file: Some(file), previous })
    }

    /// The temporary file written through `write`, given the replaced file's mode (a 0600
    /// output stays private) and flushed to the disk: renaming before the bytes are there
    /// could leave an empty file after a crash.
    fn fill(&mut self, write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>) -> io::Result<()> {
        let file = self.file.take().expect("filled once");
        let mut out = BufWriter::new(file);
        write(&mut out)?;
        let file = out.into_inner().map_err(|e| e.into_error())?;
        if let Some(meta) = &self.previous {
            file.set_permissions(meta.permissions())?;
        }
        file.sync_all()
    }

    /// Done: renamed into place (`kept`) or not, in which case the temporary file goes.
    fn end(&self, kept: bool) {
        forget_temporary(&self.temp);
        if !kept {
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

/// `write_replacing` with bytes already made.
pub fn write_bytes_replacing(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    write_replacing(path, |out| out.write_all(bytes))
}

/// An RGBA8 image of `width` × `height` as a PNG at `path`, replacing it only once complete.
pub fn write_png(path: &Path, rgba: &[u8], size: (u32, u32)) -> Result<(), WriteError> {
    check_image(path, rgba, size)?;
    write_replacing(path, |out| encode_png(out, rgba, size))
}

/// The same image as PNG bytes (for `write_all_replacing`); errors name `path`.
pub fn png_bytes(path: &Path, rgba: &[u8], size: (u32, u32)) -> Result<Vec<u8>, WriteError> {
    check_image(path, rgba, size)?;
    let mut bytes = io::Cursor::new(Vec::new());
    encode_png(&mut bytes, rgba, size).map_err(|source| WriteError::Io { path: path.to_owned(), source })?;
    Ok(bytes.into_inner())
}

/// Whether `rgba` holds a `width` × `height` image: the encoder asserts it, and a mistake must
/// be an error, not a panic.
fn check_image(path: &Path, rgba: &[u8], (width, height): (u32, u32)) -> Result<(), WriteError> {
    if (width as usize).checked_mul(height as usize).and_then(|n| n.checked_mul(4)) != Some(rgba.len()) {
        return Err(WriteError::refused(path, format!("{} bytes are not a {width}×{height} RGBA image", rgba.len())));
    }
    Ok(())
}

fn encode_png(out: &mut (impl Write + io::Seek), rgba: &[u8], (width, height): (u32, u32)) -> io::Result<()> {
    image::write_buffer_with_format(out, rgba, width, height, image::ExtendedColorType::Rgba8, image::ImageFormat::Png)
        .map_err(io::Error::other)
}

/// Several outputs replaced together: every one written beside its target and on disk before
/// any is renamed into place, so a failure (a full disk, a bad path) leaves all of them as
/// they were — results that belong together (a table, its JSON and its plot) never mix two
/// runs. (The renames themselves follow one another.)
pub fn write_all_replacing(outputs: &[(PathBuf, &[u8])]) -> Result<(), WriteError> {
    let mut pending: Vec<Pending> = Vec::new();
    let written = (|| {
        for (path, bytes) in outputs {
            pending.push(Pending::begin(path)?);
            let p = pending.last_mut().expect("just pushed");
            p.fill(|out| out.write_all(bytes)).map_err(|source| WriteError::Io { path: path.clone(), source })?;
        }
        for (p, (path, _)) in pending.iter().zip(outputs) {
            std::fs::rename(&p.temp, &p.target).map_err(|source| WriteError::Io { path: path.clone(), source })?;
        }
        Ok(())
    })();
    for p in &pending {
        p.end(written.is_ok());
    }
    written
}

/// The folder `path` is in ("." for a bare name).
fn parent_folder(path: &Path) -> &Path {
    path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."))
}

/// The longest file name the temporary name takes from its target: with the dot, the process
/// id and the suffix it stays within the 255 bytes file systems allow, whatever the target's
/// own name.
const TEMPORARY_NAME_BYTES: usize = 200;

/// A new file beside `target` (hidden, named after it and this process, never an existing
/// file), registered for removal on a signal; errors name `shown`, the path the user gave.
/// An existing target this process may not write is refused rather than replaced around it
/// (a rename needs only the folder's permission).
fn create_temporary(shown: &Path, target: &Path) -> Result<(File, PathBuf), WriteError> {
    if target.exists() && !may_write(target) {
        return Err(WriteError::refused(shown, "it is read-only to this user (its permissions say so; it is not replaced)"));
    }
    let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut cut = name.len().min(TEMPORARY_NAME_BYTES);
    while !name.is_char_boundary(cut) {
        cut -= 1;
    }
    let folder = parent_folder(target);
    let mut last = None;
    for attempt in 0..16u32 {
        let temp = folder.join(format!(".{}.{}-{attempt}.partial", &name[..cut], std::process::id()));
        let mut temps = TEMPORARIES.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        match OpenOptions::new().write(true).create_new(true).open(&temp) {
            Ok(file) => {
                temps.push(temp.clone());
                return Ok((file, temp));
            }
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last = Some(e),
            Err(source) => return Err(WriteError::Io { path: shown.to_owned(), source }),
        }
    }
    Err(WriteError::Io { path: shown.to_owned(), source: last.expect("sixteen attempts made") })
}

/// Whether this process may write `path` (the permission bits and who owns it, as the kernel
/// decides them).
#[cfg(unix)]
fn may_write(path: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    match std::ffi::CString::new(path.as_os_str().as_bytes()) {
        // SAFETY: a valid, NUL-terminated path; access() only reads it.
        Ok(c) => unsafe { libc::access(c.as_ptr(), libc::W_OK) == 0 },
        Err(_) => false,
    }
}

#[cfg(not(unix))]
fn may_write(path: &Path) -> bool {
    std::fs::metadata(path).map(|m| !m.permissions().readonly()).unwrap_or(false)
}

/// Why a file could not be read (the path is named by whoever asked for it).
#[derive(Debug, Error)]
pub enum ReadError {
    #[error("cannot read it: {0}")]
    Io(io::Error),
    #[error("it is a directory, not a file")]
    Directory,
    #[error("it is not a regular file (a device, pipe or socket)")]
    NotRegular,
    #[error("{bytes} bytes is more than the {max} we read")]
    TooLarge { bytes: u64, max: u64 },
    /// More bytes arrived than its size said (it grew while read).
    #[error("it holds more than the {max} bytes we read")]
    TooLong { max: u64 },
}

/// `path` opened for reading, at once even where it is a pipe no one writes to (O_NONBLOCK:
/// a regular file reads as ever with it; a pipe put in the file's place since it was checked
/// is then refused as opened, not waited on).
fn open_without_waiting(path: &Path) -> io::Result<File> {
    let mut options = OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NONBLOCK);
    options.open(path)
}

/// Directories and anything that is not a regular file: a device never ends (/dev/zero), a
/// pipe blocks until someone writes to it.
fn check_regular(meta: &std::fs::Metadata) -> Result<(), ReadError> {
    match meta {
        m if m.is_dir() => Err(ReadError::Directory),
        m if !m.is_file() => Err(ReadError::NotRegular),
        _ => Ok(()),
    }
}

/// The whole of the regular file at `path` (a link to one is followed), at most `max` bytes.
/// Anything else is refused before it is opened; the file is opened without waiting (so a
/// pipe put in its place since is refused too, not waited on), checked again as opened, and
/// read through a cap on the bytes that actually arrive, whatever its size said.
pub fn read_regular(path: &Path, max: u64) -> Result<Vec<u8>, ReadError> {
    let check = |meta: &std::fs::Metadata| {
        check_regular(meta)?;
        if meta.len() > max {
            return Err(ReadError::TooLarge { bytes: meta.len(), max });
        }
        Ok(())
    };
    check(&std::fs::metadata(path).map_err(ReadError::Io)?)?;
    let file = open_without_waiting(path).map_err(ReadError::Io)?;
    let meta = file.metadata().map_err(ReadError::Io)?;
    check(&meta)?;
    // The size said is only a hint for the allocation; the cap is on what is read.
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max.saturating_add(1)).read_to_end(&mut bytes).map_err(ReadError::Io)?;
    if bytes.len() as u64 > max {
        return Err(ReadError::TooLong { max });
    }
    Ok(bytes)
}

/// What the loaders' tests of hostile files share.
#[cfg(all(test, unix))]
pub(crate) mod hostile {
    use std::path::{Path, PathBuf};

    /// A new empty folder of the system's temporary one, for test `name`.
    pub fn folder(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("ml-hostile-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// A named pipe `name` in `d` (made by mkfifo(1): std cannot make one), no one writing.
    pub fn fifo(d: &Path, name: &str) -> PathBuf {
        let path = d.join(name);
        let made = std::process::Command::new("mkfifo").arg(&path).status().expect("mkfifo runs");
        assert!(made.success(), "mkfifo {}", path.display());
        path
    }

    /// A symbolic link `name` in `d` to `target`.
    pub fn link(d: &Path, name: &str, target: impl AsRef<Path>) -> PathBuf {
        let path = d.join(name);
        std::os::unix::fs::symlink(target, &path).unwrap();
        path
    }

    /// `load` refuses within a second, with an error that says `expected`.
    pub fn refused_at_once<E: std::fmt::Display>(what: &str, expected: &str, load: impl FnOnce() -> Result<(), E>) {
        let start = std::time::Instant::now();
        let error = match load() {
            Ok(()) => panic!("{what}: loaded"),
            Err(e) => e.to_string(),
        };
        assert!(start.elapsed().as_secs_f32() < 1.0, "{what}: {:?}", start.elapsed());
        assert!(error.contains(expected), "{what}: '{expected}' missing from: {error}");
    }
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

    /// A replaced output keeps its mode; a name of 255 bytes (the most a file system takes)
    /// is written, its temporary name shortened; a temporary file is registered for removal.
    #[cfg(unix)]
    #[test]
    fn a_replacement_keeps_the_mode_and_any_name_fits() {
        use std::os::unix::fs::PermissionsExt;
        let d = dir("mode-and-names");
        let private = d.join("private.bin");
        std::fs::write(&private, b"old").unwrap();
        std::fs::set_permissions(&private, std::fs::Permissions::from_mode(0o600)).unwrap();
        write_bytes_replacing(&private, b"new").unwrap();
        assert_eq!(std::fs::metadata(&private).unwrap().permissions().mode() & 0o777, 0o600);
        assert_eq!(std::fs::read(&private).unwrap(), b"new");
        for name in ["a".repeat(255), "é".repeat(127)] {
            let long = d.join(&name);
            write_bytes_replacing(&long, b"long").unwrap_or_else(|e| panic!("{} bytes: {e}", name.len()));
            write_bytes_replacing(&long, b"again").unwrap();
            assert_eq!(std::fs::read(&long).unwrap(), b"again");
        }
        // (remove_temporaries itself would take other tests' files: the command-line test
        // interrupts a sequence.)
        let (_, temp) = create_temporary(&private, &private).unwrap();
        assert!(TEMPORARIES.lock().unwrap().contains(&temp), "a temporary file not registered for removal");
        forget_temporary(&temp);
        std::fs::remove_file(&temp).unwrap();
        let left: Vec<String> = entries(&d).into_iter().filter(|e| e.ends_with(".partial")).collect();
        assert!(left.is_empty(), "{left:?}");
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

    #[test]
    fn a_regular_file_is_read_whole_up_to_its_cap() {
        let d = dir("read");
        let path = d.join("scene.toml");
        std::fs::write(&path, b"twelve bytes").unwrap();
        assert_eq!(read_regular(&path, 12).unwrap(), b"twelve bytes");
        let e = read_regular(&path, 11).unwrap_err();
        assert!(matches!(e, ReadError::TooLarge { bytes: 12, max: 11 }), "{e}");
        assert_eq!(e.to_string(), "12 bytes is more than the 11 we read");
        // A link to a regular file is followed.
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&path, d.join("link.toml")).unwrap();
            assert_eq!(read_regular(&d.join("link.toml"), 100).unwrap(), b"twelve bytes");
        }
        assert!(read_regular(&d.join("missing"), 100).unwrap_err().to_string().starts_with("cannot read it: "));
        assert_eq!(read_regular(&d, 100).unwrap_err().to_string(), "it is a directory, not a file");
    }

    /// Devices, pipes and links to them are refused at once: read whole, /dev/zero would fill
    /// the memory, and a pipe no one writes to would wait forever.
    #[cfg(unix)]
    #[test]
    fn devices_and_pipes_are_refused_at_once() {
        let d = dir("devices");
        let pipe = hostile::fifo(&d, "scene.toml");
        let zero_link = d.join("zero.glb");
        std::os::unix::fs::symlink("/dev/zero", &zero_link).unwrap();
        for path in [Path::new("/dev/zero"), Path::new("/dev/urandom"), Path::new("/dev/null"), &pipe, &zero_link] {
            let start = std::time::Instant::now();
            let e = read_regular(path, 1 << 30).unwrap_err();
            assert!(start.elapsed().as_secs_f32() < 1.0, "{}: {:?}", path.display(), start.elapsed());
            assert!(matches!(e, ReadError::NotRegular), "{}: {e}", path.display());
            assert_eq!(e.to_string(), "it is not a regular file (a device, pipe or socket)");
        }
    }

    /// A pipe put in a file's place after the check is opened without waiting for a writer,
    /// and refused as opened.
    #[cfg(unix)]
    #[test]
    fn a_pipe_is_opened_without_waiting_and_refused_as_opened() {
        let d = dir("swapped");
        let pipe = hostile::fifo(&d, "buffer.bin");
        let start = std::time::Instant::now();
        let file = open_without_waiting(&pipe).unwrap();
        assert!(matches!(check_regular(&file.metadata().unwrap()), Err(ReadError::NotRegular)));
        assert!(start.elapsed().as_secs_f32() < 1.0, "{:?}", start.elapsed());
    }

    /// The cap is on the bytes read, not on the size the file claims: a file of /proc says it
    /// has 0 bytes and holds more.
    #[cfg(target_os = "linux")]
    #[test]
    fn the_cap_holds_whatever_size_the_file_claims() {
        let status = Path::new("/proc/self/status");
        assert_eq!(std::fs::metadata(status).unwrap().len(), 0);
        let e = read_regular(status, 16).unwrap_err();
        assert!(matches!(e, ReadError::TooLong { max: 16 }), "{e}");
        assert_eq!(e.to_string(), "it holds more than the 16 bytes we read");
        assert!(read_regular(status, 1 << 20).unwrap().starts_with(b"Name:"));
    }
}
