//! What the scene-file and glTF loaders share: reading the files they name, never outside
//! their folder, and what a loaded file gives.

use crate::files::{read_regular, ReadError};
use crate::scene::Scene;
use std::path::{Component, Path};
use thiserror::Error;

/// Most objects a scene may hold, whichever file it came from.
pub const MAX_OBJECTS: usize = 1 << 20;

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
