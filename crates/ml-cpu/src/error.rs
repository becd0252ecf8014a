use crate::limits::{MAX_BENCH_OBJECTS, MAX_CLUSTERS, MAX_LIGHTS, MAX_LIGHT_MARKERS};
use thiserror::Error;

/// What can be wrong with a scene request before any GPU work starts: a name nothing has, a
/// count or size out of range. The messages name the setting, not how a command spells it.
#[derive(Debug, Error, PartialEq)]
pub enum SceneError {
    #[error("light count {0} is out of range: use 1 to {max}", max = MAX_LIGHTS)]
    LightCount(u64),
    #[error("bench object count {0} is out of range: use 0 to {max}", max = MAX_BENCH_OBJECTS)]
    ObjectCount(usize),
    #[error("light radius {0} is invalid: radii must be finite and > 0 (R or MIN..MAX with MIN <= MAX)")]
    LightRadius(String),
    #[error("cluster grid {0} is invalid: use XxYxZ with each at least 1 and at most {max} clusters in all", max = MAX_CLUSTERS)]
    Clusters(String),
    #[error("{0} lights are too many to show: each is drawn as an object, at most {max}", max = MAX_LIGHT_MARKERS)]
    TooManyMarkers(usize),
    #[error("the surface light layout needs a scene with surfaces (triangles of non-zero area)")]
    NoSurface,
    #[error("the lights fitted to the scene's box would get radius {}: the box has no usable size", Number(*.0))]
    FittedRadius(f32),
    #[error("unknown {kind} '{name}': expected one of {expected}")]
    UnknownName { kind: &'static str, name: String, expected: String },
}

/// A number as an error shows it: as written for everyday sizes, in exponent form for the very
/// large and very small ("1e38", not thirty-nine digits).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Number(pub f32);

impl std::fmt::Display for Number {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let size = self.0.abs();
        if size == 0.0 || (1e-4..1e7).contains(&size) || !size.is_finite() {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// The one of `all` that `name_of` calls `name`; else an `UnknownName` of `kind` that lists
/// every name.
pub(crate) fn find_named<T: Copy>(kind: &'static str, all: &[T], name_of: impl Fn(T) -> &'static str, name: &str) -> Result<T, SceneError> {
    all.iter().copied().find(|&t| name_of(t) == name).ok_or_else(|| SceneError::UnknownName {
        kind,
        name: name.to_owned(),
        expected: all.iter().map(|&t| name_of(t)).collect::<Vec<_>>().join(", "),
    })
}
