//! What the scene-file and glTF loaders share: reading a file of bounded size, and what a
//! loaded file gives.

use crate::scene::Scene;
use std::path::Path;
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

/// Why a file could not be read (the path is named by whoever opened it).
#[derive(Debug, Error)]
pub enum ReadError {
    #[error("cannot read it: {0}")]
    Io(std::io::Error),
    #[error("it is a directory, not a file")]
    Directory,
    #[error("{bytes} bytes is more than the {max} we read")]
    TooLarge { bytes: u64, max: u64 },
}

/// Read a whole file of at most `max` bytes, refusing directories and missing files.
pub fn read_capped(path: &Path, max: u64) -> Result<Vec<u8>, ReadError> {
    let meta = std::fs::metadata(path).map_err(ReadError::Io)?;
    if meta.is_dir() {
        return Err(ReadError::Directory);
    }
    if meta.len() > max {
        return Err(ReadError::TooLarge { bytes: meta.len(), max });
    }
    std::fs::read(path).map_err(ReadError::Io)
}
