//! How a feature's scene section (`scene_section`) is read from its table of a scene file and
//! what a request (the command line, the window) may ask of it: a `SectionKind`, declared in
//! the feature's module and listed in `sections::SECTIONS`, a line each — the scene, the scene
//! file and the request name no feature.

use crate::file_fields::FieldProblem;
use crate::scene::Scene;
use crate::scene_section::{Section, Sections};
use crate::shading_model::ShadingModel;
use std::path::Path;

/// What a feature's table of a scene file is read with.
pub struct FileSite<'a> {
    /// The scene file's folder (files the table names are relative to it); None: text
    /// without a file.
    pub folder: Option<&'a Path>,
    /// The request replaces the section (`SectionKind::replaces_file`): the table is checked
    /// but nothing it names is read, and it gives no section.
    pub replaced: bool,
}

/// What a request's section asks is applied with.
pub struct RequestSite {
    pub shading: ShadingModel,
}

/// Why a feature's table of a scene file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SectionError {
    /// It does not fit the feature's format (an unknown field, a wrong type): the TOML
    /// reader's error, which knows where.
    #[error("{0}")]
    Format(#[from] toml::de::Error),
    #[error(transparent)]
    Field(#[from] FieldProblem),
    /// It names a file, and the scene was read without a folder.
    #[error("names a file, and the scene has no folder (load it from a file)")]
    NoFolder,
    /// What it names could not be used (a file that does not load).
    #[error("{0}")]
    Unusable(String),
}

/// An error of a request's section (its file that does not load).
pub type AskError = Box<dyn std::error::Error + Send + Sync>;

/// How a feature reads its table: the section it gives (None: it asks for none).
pub type ReadTable = fn(toml::de::ValueDeserializer<'_>, &FileSite) -> Result<Option<Box<dyn Section>>, SectionError>;

/// How a feature's section is read and asked for.
pub struct SectionKind {
    /// Its table's name in a scene file (`[environment]`).
    pub table: &'static str,
    /// Its table read and checked (None: it asks for no section).
    pub read: ReadTable,
    /// Whether a request's `asks` replace a scene file's section (its table is then checked,
    /// not loaded).
    pub replaces_file: fn(asks: &Sections) -> bool,
    /// A scene file with no light of its own, as the request builds it: the section it gets
    /// when the file gives none.
    pub unlit_file: fn(asks: &Sections, scene: &mut Scene, site: &RequestSite),
    /// What a request asks of the section, applied to the scene it built.
    pub apply: fn(asks: &Sections, scene: &mut Scene, site: &RequestSite) -> Result<(), AskError>,
}
