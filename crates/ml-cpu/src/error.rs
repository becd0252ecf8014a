use thiserror::Error;

/// What can be wrong with a scene request before any GPU work starts.
#[derive(Debug, Error, PartialEq)]
pub enum SceneError {
    #[error("--lights {0} is out of range: use 1 to {max}", max = crate::lights::MAX_LIGHTS)]
    LightCount(u64),
    #[error("light radius {0} is invalid: radii must be finite and > 0 (R or MIN..MAX with MIN <= MAX)")]
    LightRadius(String),
    #[error("--clusters {0} is invalid: use XxYxZ with each at least 1 and at most {max} clusters in all", max = crate::cluster::ClusterDims::MAX_CLUSTERS)]
    Clusters(String),
    #[error("unknown {kind} '{name}': expected one of {expected}")]
    UnknownName { kind: &'static str, name: String, expected: String },
}
