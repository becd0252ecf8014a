//! What the scene-file and glTF loaders share: reading the files they name, never outside
//! their folder, and what a loaded file gives.

use crate::error::Number;
use crate::files::{read_regular, ReadError};
use crate::limits::{LENGTHS, MAX_COORDINATE, MAX_DRAWN_TRIANGLES};
use crate::mesh::MeshKind;
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

/// A scene whose placements draw more than MAX_DRAWN_TRIANGLES a frame, and the mesh that
/// draws the most of them.
#[derive(Debug, Error, PartialEq)]
#[error("the scene draws {triangles} triangles a frame, more than {max}: most of them {mesh} of {each} triangles placed {placed} times", max = MAX_DRAWN_TRIANGLES)]
pub struct DrawWorkError {
    pub triangles: u64,
    pub mesh: String,
    pub each: u64,
    pub placed: u64,
}

/// Whether `scene` draws at most MAX_DRAWN_TRIANGLES a frame: its objects' meshes' triangles,
/// each placement counted (from the meshes' index counts: nothing is uploaded before).
pub fn check_draw_work(scene: &Scene) -> Result<(), DrawWorkError> {
    // Placements per mesh: the scene's own by index, the built-in kinds after them.
    let kinds = MeshKind::ALL;
    let mut placed = vec![0u64; scene.meshes.len() + kinds.len()];
    for o in &scene.objects {
        let slot = match o.mesh {
            MeshKind::Loaded(i) => i as usize,
            kind => scene.meshes.len() + kinds.iter().position(|&k| k == kind).unwrap_or(0),
        };
        if let Some(count) = placed.get_mut(slot) {
            *count += 1;
        }
    }
    let triangles_of = |slot: usize| -> u64 {
        match scene.meshes.get(slot) {
            Some(mesh) => mesh.indices.len() as u64 / 3,
            None => kinds[slot - scene.meshes.len()].build().indices.len() as u64 / 3,
        }
    };
    // Per mesh placed: (its slot, its triangles, its placements), each mesh counted once.
    let drawn: Vec<(usize, u64, u64)> =
        placed.iter().enumerate().filter(|(_, &n)| n > 0).map(|(slot, &n)| (slot, triangles_of(slot), n)).collect();
    let triangles: u64 = drawn.iter().map(|&(_, each, n)| each * n).sum();
    if triangles <= MAX_DRAWN_TRIANGLES {
        return Ok(());
    }
    let &(slot, each, placed) = drawn.iter().max_by_key(|&&(_, each, n)| each * n).expect("triangles drawn");
    let mesh = match scene.meshes.get(slot) {
        Some(_) => "a mesh".to_owned(),
        None => format!("the built-in {}", kinds[slot - scene.meshes.len()].name()),
    };
    Err(DrawWorkError { triangles, mesh, each, placed })
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
    /// Through a symbolic link, out of the folder or to nothing: one answer for both, so that
    /// an error never tells whether a file exists outside the folder.
    #[error("it leads out of the folder of the file that names it, or to no file, through a link")]
    ThroughLink,
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
    let inside = folder.canonicalize().map_err(io)?;
    let through_link = passes_a_link(folder, reference);
    let resolved = match folder.join(reference).canonicalize() {
        Ok(resolved) => resolved,
        Err(_) if through_link => return Err(ReferenceError::ThroughLink),
        Err(e) => return Err(io(e)),
    };
    if !resolved.starts_with(&inside) {
        return Err(if through_link { ReferenceError::ThroughLink } else { ReferenceError::OutsideFolder });
    }
    Ok(read_regular(&resolved, max)?)
}

/// Whether `reference`, followed from `folder` one name at a time, meets a symbolic link.
fn passes_a_link(folder: &Path, reference: &Path) -> bool {
    let mut path = folder.to_path_buf();
    for part in reference.components() {
        match part {
            Component::ParentDir => {
                path.pop();
            }
            Component::Normal(name) => {
                path.push(name);
                if std::fs::symlink_metadata(&path).is_ok_and(|m| m.file_type().is_symlink()) {
                    return true;
                }
            }
            _ => {}
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::material::Material;
    use crate::mesh::Mesh;
    use crate::scene::Object;
    use glam::Vec3;

    /// A mesh of 2^20 triangles placed 1,024 times draws MAX_DRAWN_TRIANGLES: it renders; once
    /// more is refused, naming it; the built-in kinds count their own triangles.
    #[test]
    fn placements_count_every_triangle_they_draw() {
        let mesh = Mesh { vertices: Vec::new(), indices: vec![0; 3 << 20] };
        let placed = |n: usize, extra: MeshKind| {
            let mut objects: Vec<Object> =
                (0..n).map(|_| Object::placed(MeshKind::Loaded(0), Vec3::ZERO, 1.0, Material::built_in()[0])).collect();
            objects.push(Object::placed(extra, Vec3::ZERO, 1.0, Material::built_in()[0]));
            let mut scene = Scene::new(objects, Vec::new(), Camera::seed());
            scene.meshes = vec![mesh.clone()];
            check_draw_work(&scene)
        };
        let plane = MeshKind::Plane.build().indices.len() as u64 / 3;
        assert_eq!(placed(1023, MeshKind::Plane), Ok(()));
        let e = placed(1024, MeshKind::Plane).unwrap_err();
        assert_eq!(e, DrawWorkError { triangles: (1 << 30) + plane, mesh: "a mesh".into(), each: 1 << 20, placed: 1024 });
        assert!(e.to_string().contains("more than 1073741824: most of them a mesh of 1048576 triangles placed 1024 times"), "{e}");
    }
}
