//! The limits and value ranges that more than one module checks or names: how much a request
//! may ask for (lights, bench objects, clusters, light markers) and what a scene file or glTF
//! file may give (objects, coordinates, lengths, scales, intensities). A leaf, it uses nothing
//! of the crate: `SceneError`'s messages name these limits, and the modules that check them
//! return `SceneError`, so the limits cannot live in those modules without a circle.

use std::ops::RangeInclusive;

/// The most lights a scene may hold (67.1 M × 32 B = 2 GiB of light data, where the device
/// binds that much). Millions are what the light grid is built for; beyond this is a typo,
/// not a workload.
pub const MAX_LIGHTS: u64 = 1 << 26;

/// The most objects the bench scene places (a million-triangle mesh budget per hundred).
pub const MAX_BENCH_OBJECTS: usize = 100_000;

/// The largest cluster grid we accept (a million clusters: the CPU assignment's lists are
/// rebuilt and uploaded every frame).
pub const MAX_CLUSTERS: u64 = 1 << 20;

/// Most lights `--show-lights` draws: each marker is an object of its own (one draw each in
/// the forward techniques).
pub const MAX_LIGHT_MARKERS: usize = 65_536;

/// Most triangles a scene may draw a frame, each placement of a mesh counted (2^30): the H200
/// draws a tree placed to 269 M triangles in 28.5 ms a frame, so this is seconds a frame on a
/// GPU and hours on a CPU driver — a file past it (a mesh placed thousands of times) is
/// refused, not rendered unbounded.
pub const MAX_DRAWN_TRIANGLES: u64 = 1 << 30;

/// Most objects a scene may hold, whichever file it came from.
pub const MAX_OBJECTS: usize = 1 << 20;

/// Largest |coordinate| of anything a file places (objects' boxes, lights, the camera): a
/// thousand kilometres in metres, a kilometre in millimetres. Beyond, f32 keeps too few digits
/// for the model, and its depth range for the camera.
pub const MAX_COORDINATE: f32 = 1e6;
/// A perspective camera's vertical field of view in degrees: at least this (a narrower one
/// magnifies past what f32 depth and positions resolve), and below 180.
pub const MIN_FOV_Y_DEG: f32 = 0.01;
/// Lengths a file gives: light radii, near and far planes, an orthographic camera's half-height.
pub const LENGTHS: RangeInclusive<f32> = 1e-6..=1e7;
/// Scales: a scene file's objects, each axis of a glTF node's transform.
pub const SCALES: RangeInclusive<f32> = 1e-6..=1e6;
/// Largest light colour (glTF: colour × intensity, sunlight being about 1e5 lux), ambient
/// term and emissive strength.
pub const MAX_INTENSITY: f32 = 1e7;
