//! The renderer's errors. Settings errors carry the names of the choices they are about
//! (`Technique::name`, ...) rather than the choices, so this module depends on no settings.

use thiserror::Error;

#[derive(Debug, Error)]
pub enum RenderError {
    #[error(transparent)]
    Vulkan(#[from] ml_vk::VkError),
    #[error(transparent)]
    Scene(#[from] ml_cpu::SceneError),
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// A name that is none of `kind`'s; `expected` lists them.
    #[error("unknown {kind} '{name}': expected one of {expected}")]
    UnknownName { kind: Named, name: String, expected: String },
    #[error("{0}: use fewer or smaller lights, a coarser cluster grid, or a technique with the light grid (clustered-gpu, deferred-compute, visibility)")]
    ListsTooLong(ListsTooLong),
    /// What the scene or the settings ask for cannot be done (one line saying why).
    #[error("{0}")]
    Invalid(String),
    /// A bug: something the renderer should have made first is not there.
    #[error("internal error (a bug in manylights): {0}")]
    Internal(String),
}

/// Cluster light lists longer than what `holder` can take: `needed` entries against `limit`,
/// in `technique` (named where the renderer knows it).
#[derive(Debug, Error, PartialEq)]
#[error("{}the cluster light lists need at least {needed} entries ({} MiB), more than the {} MiB {holder}", technique.map_or(String::new(), |t| format!("{t}: ")), mib_up(*needed), mib(*limit))]
pub struct ListsTooLong {
    pub needed: usize,
    pub limit: usize,
    /// What the limit is, in words ("'lavapipe' binds as one storage buffer").
    pub holder: String,
    /// The technique's name.
    pub technique: Option<&'static str>,
}

impl RenderError {
    /// The error, where it is about light lists that do not fit, naming the technique (its
    /// `name`).
    pub fn in_technique(self, technique: &'static str) -> RenderError {
        match self {
            RenderError::ListsTooLong(lists) => RenderError::ListsTooLong(ListsTooLong { technique: Some(technique), ..lists }),
            other => other,
        }
    }
}

/// MiB of `entries` light indices (4 bytes each), rounded down.
fn mib(entries: usize) -> u64 {
    (entries as u64 * 4) >> 20
}

/// MiB of `entries` light indices, rounded up (what is needed is never said smaller than it is).
fn mib_up(entries: usize) -> u64 {
    (entries as u64 * 4).div_ceil(1 << 20)
}

/// What a name given to `from_name` was meant to be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Named {
    Technique,
    DebugView,
    OmniShadowMode,
    SunShadowMode,
    Raster,
    LightGridMarks,
    Antialiasing,
    Background,
}

impl std::fmt::Display for Named {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(match self {
            Named::Technique => "technique",
            Named::DebugView => "debug view",
            Named::OmniShadowMode => "point-light shadow mode",
            Named::SunShadowMode => "sun shadow mode",
            Named::Raster => "rasteriser",
            Named::LightGridMarks => "light grid marks choice",
            Named::Antialiasing => "anti-aliasing sample count",
            Named::Background => "background",
        })
    }
}

/// A number of the settings an error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Setting {
    Width,
    Height,
    /// Texels per side of a shadow-cube face.
    CubeSize,
    /// The compute raster's largest triangle (pixels a side of its bounding box).
    RasterSplit,
    /// Transparent nodes per pixel (`--transparency-budget`).
    TransparencyBudget,
}

impl std::fmt::Display for Setting {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(match self {
            Setting::Width => "width",
            Setting::Height => "height",
            Setting::CubeSize => "cube size",
            Setting::RasterSplit => "raster split",
            Setting::TransparencyBudget => "transparency budget",
        })
    }
}

/// Settings the device, the scene or each other refuse (`RenderSettings::check`), found
/// before anything is allocated.
#[derive(Debug, Error, PartialEq)]
pub enum SettingsError {
    #[error("'{device}' lacks the imageCubeArray feature, which every shading pipeline needs (point-light shadow cubes)")]
    NoCubeArrays { device: String },
    #[error("{what} {value} is out of range: use 1 to {max}")]
    OutOfRange { what: Setting, value: u32, max: u32 },
    /// A debug view whose feature is not in the settings (what it needs: `ViewNeed`).
    #[error("the {view} debug view needs {needs}, not {instead}")]
    ViewNeeds { view: &'static str, needs: String, instead: String },
    /// What a feature refuses of a scene under the settings (`Feature::check_scene`), in its
    /// own words.
    #[error("{0}")]
    SceneRefused(&'static str),
    #[error("--light-stats counts the light loop of the compute-lit techniques (deferred-compute, visibility), not {technique}'s")]
    LightStatsNeedCompute { technique: &'static str },
    #[error("the {technique} technique needs {feature}, which '{device}' lacks: use deferred-compute")]
    TechniqueFeature { technique: &'static str, feature: &'static str, device: String },
    #[error("the compute raster draws the visibility buffer of the visibility technique, not {technique}'s (use --raster hardware)")]
    RasterNeedsVisibility { technique: &'static str },
    #[error("the {raster} raster needs {feature}, which '{device}' lacks: use --raster hardware")]
    RasterFeature { raster: &'static str, feature: &'static str, device: String },
    #[error("the compute raster's buffer for {width}x{height} takes {bytes} bytes but '{device}' allows {max} bytes per storage buffer: use a smaller size, fewer --aa samples or --raster hardware (without --aa)")]
    RasterBuffer { width: u32, height: u32, bytes: u64, device: String, max: u32 },
    /// Anti-aliasing's samples: the compute raster's buffer, the mesh techniques' multisampled
    /// attachments.
    #[error(
        "--light-stats with --aa {samples}: {technique}'s light counts read a single-sampled depth target: use --aa off, or visibility"
    )]
    LightStatsWithSamples { samples: &'static str, technique: &'static str },
    #[error("--aa {samples} needs {feature}, which '{device}' lacks: use --aa off")]
    AntialiasingFeature { samples: &'static str, feature: &'static str, device: String },
    #[error(
        "--aa {samples}: '{device}' draws {what} with {offered} samples a pixel, not {samples}: use --aa with one of those or --aa off"
    )]
    AntialiasingSamples { samples: &'static str, what: String, device: String, offered: String },
    #[error("the scene has transparent (BLEND) materials, whose layers are anti-aliased by the visibility technique at up to {max} samples a pixel, not by {technique} at {samples}: use --technique visibility with --aa 4 or 8, or --aa off")]
    AntialiasingWithLayers { samples: &'static str, technique: &'static str, max: u32 },
    #[error(
        "a transparency budget of {budget} nodes per pixel at {width}x{height} takes {bytes} bytes but '{device}' allows {max} bytes per storage buffer: lower --transparency-budget"
    )]
    TransparencyPool { budget: u32, width: u32, height: u32, bytes: u64, device: String, max: u32 },
    #[error(
        "the compute raster's list of {bins} large triangles takes {bytes} bytes but '{device}' allows {max} bytes per storage buffer"
    )]
    BinList { bins: u32, bytes: u64, device: String, max: u32 },
    /// The sun's shadow map in compute: 64-bit integers (the large triangles' edge functions)
    /// and a D32_SFLOAT depth image to copy the depths into.
    #[error("the sun's shadow map drawn in compute needs {feature}, which '{device}' lacks: use the graphics sun shadow")]
    SunShadowFeature { feature: &'static str, device: String },
    #[error("frames must be at least 1")]
    NoFrames,
    #[error("time {0} is not a finite number")]
    Time(f32),
    #[error("{lights} lights need {bytes} bytes of light buffer but '{device}' allows {max} bytes per storage buffer")]
    LightBuffer { lights: usize, bytes: u64, device: String, max: u32 },
    #[error("point-light shadows need point lights (shadow rays: or directional lights), and the scene has none")]
    ShadowsWithoutLights,
    #[error("{value} shadowed lights is out of range: the scene has {lights} lights (use 1 to {lights})")]
    ShadowedLights { value: u32, lights: usize },
    #[error("the shadow atlas takes at most {max} shadowed lights, not {value}")]
    TooManyShadowed { value: u32, max: u32 },
    #[error("a shadow budget of {mib} MiB is out of range: 1 to {max_mib} MiB (the device memory of '{device}')")]
    ShadowBudget { mib: u32, max_mib: u64, device: String },
    #[error("--cube-size {value} with the shadow atlas: every face's size must be a power of two from {min} to {max}")]
    AtlasFaceSize { value: u32, min: u32, max: u32 },
    #[error("{value} shadowed lights is more than the {max} shadow cubes '{device}' holds in one array")]
    TooManyCubes { value: u32, max: u32, device: String },
    #[error("{lights} shadow cubes of {size}² take {mib} MiB, more than the {max_mib} MiB we allow")]
    ShadowMemory { lights: u32, size: u32, mib: u64, max_mib: u64 },
    #[error("{lights} shadow cubes of {size}² drawn in compute take a {mib} MiB buffer, more than the {max_mib} MiB '{device}' allows per storage buffer")]
    ShadowBuffer { lights: u32, size: u32, mib: u64, device: String, max_mib: u64 },
    /// A way of rendering the cubes that needs a feature the device lacks; `instead`: the
    /// modes to use.
    #[error("{mode} point-light shadows need the {feature} feature, which '{device}' lacks: use {instead}")]
    MissingFeature { mode: &'static str, feature: &'static str, device: String, instead: &'static str },
    /// A depth-only multiview pass that the driver renders wrong (multiview_depth_is_broken).
    #[error("multiview point-light shadows: '{device}' ({driver}) renders every view of a depth-only multiview pass into the first layer (measured on Mesa 22.3 lavapipe): use layered, direct or copy")]
    BrokenMultiview { device: String, driver: String },
}

/// The one of `all` whose name (`name_of`) is `name`; else the error that lists the names.
/// `a`, `a or b`, `a, b or c`.
pub fn or_list<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let names: Vec<&str> = names.collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => names.join(""),
    }
}

pub(crate) fn by_name<T: Copy>(all: &[T], name_of: fn(T) -> &'static str, kind: Named, name: &str) -> Result<T, RenderError> {
    all.iter().copied().find(|&v| name_of(v) == name).ok_or_else(|| {
        let expected = all.iter().map(|&v| name_of(v)).collect::<Vec<_>>().join(", ");
        RenderError::UnknownName { kind, name: name.to_owned(), expected }
    })
}
