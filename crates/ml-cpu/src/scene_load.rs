//! What the scene-file and glTF loaders share: reading the files they name, never outside
//! their folder, and what a loaded file gives.

use crate::error::Number;
use crate::files::{read_regular, ReadError};
use crate::limits::{LENGTHS, MAX_COORDINATE};
use crate::scene::Scene;
use std::path::{Component, Path};
use thiserror::Error;

/// The least size of a scene's box (its largest side) over its distance from the origin: f32
/// keeps about 7 digits, so a model smaller than this for where it is would be crushed by
/// rounding (and the lights fitted to its box would have no size).
const LEAST_RELATIVE_SIZE: f32 = 1e-6;

/// A scene whose box cannot be rendered.
#[derive(Debug, Error, PartialEq)]
pub enum ExtentError {
    #[error("the scene's objects reach {}, beyond ±{} (glTF: the nodes' transforms included)", Number(*.0), Number(MAX_COORDINATE))]
    TooFar(f32),
    #[error("the scene's objects fit in a box {} across: too small to render (at least {} at {} from the origin)", Number(*size), Number(*least), Number(*reach))]
    TooSmall { size: f32, least: f32, reach: f32 },
}

/// Whether the box around `scene`'s objects renders: within ±MAX_COORDINATE, and not so
/// small for its place that it collapses (a degenerate box: every vertex at one point).
pub fn check_extent(scene: &Scene) -> Result<(), ExtentError> {
    let (lo, hi) = scene.bounds();
    let reach = lo.abs().max(hi.abs()).max_element();
    // (glam's max passes over NaN: finiteness is its own test.)
    if !(lo.is_finite() && hi.is_finite() && reach <= MAX_COORDINATE) {
        return Err(ExtentError::TooFar(reach));
    }
    let (size, least) = ((hi - lo).max_element(), (reach * LEAST_RELATIVE_SIZE).max(*LENGTHS.start()));
    if size < least {
        return Err(ExtentError::TooSmall { size, least, reach });
    }
    Ok(())
}

/// A loaded scene file or glTF file: the scene, the name of the shading model it asks for
/// (resolved by whoever builds the scene, who may be asked for another), and what it holds
/// that is left out.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneFile {
    pub scene: Scene,
    pub shading: Option<String>,
    pub warnings: Vec<String>,
}

/// Why a file named by a scene file or glTF file (a glTF model, a buffer, an image) could not
/// be read. The reference is named by whoever followed it; a file it was not let read is never
/// described (its size or content would tell about a file outside the model's folder).
#[derive(Debug, Error)]
pub enum ReferenceError {
    #[error("an absolute path: files are named relative to the folder of the file that names them")]
    Absolute,
    #[error("it leads out of the folder of the file that names it")]
    OutsideFolder,
    #[error(transparent)]
    Read(#[from] ReadError),
}

/// The file `reference` names, relative to `folder` (the folder of the file that names it),
/// read whole if it is a regular file of at most `max` bytes. Only files inside `folder` are
/// read: an absolute path is refused, and so is a `..` that climbs out of it; symbolic links
/// are followed where they end inside `folder` (a model may link to its textures), so the
/// path is checked again with every link resolved.
pub fn read_reference(folder: &Path, reference: &Path, max: u64) -> Result<Vec<u8>, ReferenceError> {
    let mut depth = 0usize;
    for part in reference.components() {
        match part {
            Component::Prefix(_) | Component::RootDir => return Err(ReferenceError::Absolute),
            Component::CurDir => {}
            Component::ParentDir => depth = depth.checked_sub(1).ok_or(ReferenceError::OutsideFolder)?,
            Component::Normal(_) => depth += 1,
        }
    }
    // A file named without a folder is in the current one.
    let folder = if folder.as_os_str().is_empty() { Path::new(".") } else { folder };
    let io = |e| ReferenceError::Read(ReadError::Io(e));
    let (inside, resolved) = (folder.canonicalize().map_err(io)?, folder.join(reference).canonicalize().map_err(io)?);
    if !resolved.starts_with(&inside) {
        return Err(ReferenceError::OutsideFolder);
    }
    Ok(read_regular(&resolved, max)?)
}
