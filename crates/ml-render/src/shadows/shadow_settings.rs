//! The shadow stores' settings: how point-light shadows are made (cube array modes or the
//! shadow atlas), for how many lights, how large, and who draws the sun's map. Here, beside
//! the stores they shape, so that the scene's GPU resources need nothing of the render
//! settings above them.

use crate::error::{by_name, Named, RenderError, Setting, SettingsError};
use crate::targets::MAX_DIMENSION;
use ml_vk::Context;

/// How point-light shadow cubes are rendered (docs/DESIGN.md#point-light-shadows).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum OmniShadowMode {
    /// The classic way: each face into one offscreen depth target, then copied into the cube.
    Copy,
    /// Each face straight into its cube layer (a framebuffer per layer).
    Direct,
    /// All six faces in one pass (VK_KHR_multiview, view i = face i).
    Multiview,
    /// All six faces in one pass by layered rendering: six instances of each draw, instance i
    /// writes gl_Layer = i (shaderOutputLayer).
    Layered,
    /// Compute shaders draw every face of every cube (meshlets culled per face, small
    /// triangles a thread each, large ones a work group each) into a buffer of 32-bit depths,
    /// copied into the cubes (docs/DESIGN.md#compute-shadow-raster). `large_list`: large
    /// triangles the list of its work groups holds; past it (0: always), the thread that found
    /// one draws it itself (slower, nothing lost).
    Compute { large_list: u32 },
    /// Every visible face of every shadowed light in one shadow atlas of a fixed budget, each
    /// light's faces as large as it is on screen, drawn by the compute raster; faces whose
    /// light did not move keep their texels (docs/DESIGN.md#shadow-atlas).
    Atlas(AtlasSettings),
    /// No cubes: each point a shadowed light reaches traces a shadow ray to it through the
    /// scene's triangles (docs/DESIGN.md#shadow-rays), so every light may cast shadows.
    Rays,
}

/// The shadow atlas's settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct AtlasSettings {
    /// MiB all point-light shadow memory may take: the atlas, its tables and the raster's
    /// lists.
    pub budget_mib: u32,
    /// Faces whose light did not move keep last frame's texels (off: every face is drawn
    /// every frame; the images are the same).
    pub cache: bool,
    /// Every face this many texels a side (before the budget's factor) instead of the
    /// light's size on screen (for comparisons with the cube array).
    pub fixed_size: Option<u32>,
}

impl AtlasSettings {
    pub const DEFAULT: AtlasSettings = AtlasSettings { budget_mib: 256, cache: true, fixed_size: None };

    pub fn budget_bytes(&self) -> u64 {
        (self.budget_mib as u64) << 20
    }
}

impl OmniShadowMode {
    /// The compute raster with its default list of large triangles (2^20: 8 MiB).
    pub const COMPUTE: OmniShadowMode = OmniShadowMode::Compute { large_list: 1 << 20 };

    pub const ALL: [OmniShadowMode; 7] = [
        OmniShadowMode::Copy,
        OmniShadowMode::Direct,
        OmniShadowMode::Multiview,
        OmniShadowMode::Layered,
        OmniShadowMode::COMPUTE,
        OmniShadowMode::Atlas(AtlasSettings::DEFAULT),
        OmniShadowMode::Rays,
    ];

    pub fn name(self) -> &'static str {
        match self {
            OmniShadowMode::Copy => "copy",
            OmniShadowMode::Direct => "direct",
            OmniShadowMode::Multiview => "multiview",
            OmniShadowMode::Layered => "layered",
            OmniShadowMode::Compute { .. } => "compute",
            OmniShadowMode::Atlas(_) => "atlas",
            OmniShadowMode::Rays => "rays",
        }
    }

    pub fn from_name(name: &str) -> Result<OmniShadowMode, RenderError> {
        by_name(&OmniShadowMode::ALL, OmniShadowMode::name, Named::OmniShadowMode, name)
    }
}

/// Point-light shadows: how the cubes are made, for how many lights, how large.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct OmniShadowSettings {
    pub mode: OmniShadowMode,
    /// Lights with a shadow cube (the strongest as seen from the camera), at most; with
    /// `all`, the lights that reach the view (SettingsRequest::for_scene counts them); with
    /// shadow rays, every light.
    pub lights: u32,
    /// Shadow every light that reaches the view (at most MAX_SHADOWED_LIGHTS; with shadow
    /// rays every light, no cap), not the `lights` strongest.
    pub all: bool,
    /// Texels per side of each cube face (cube array modes).
    pub size: u32,
}

/// The most lights `--shadowed-lights all` shadows (the strongest first), and the most the
/// shadow atlas takes.
pub const MAX_SHADOWED_LIGHTS: u32 = 4096;

impl OmniShadowSettings {
    pub const DEFAULT_SIZE: u32 = 1024;

    /// The shadow atlas's settings, if the faces go into one.
    pub fn atlas(&self) -> Option<AtlasSettings> {
        match self.mode {
            OmniShadowMode::Atlas(a) => Some(a),
            _ => None,
        }
    }

    /// Whether shadowed lights are tested by shadow rays (no cubes).
    pub fn rays(&self) -> bool {
        self.mode == OmniShadowMode::Rays
    }

    /// Bytes of the cube array (32-bit depth; the shadow atlas's are its budget; shadow rays
    /// have none: their hierarchy is the scene's).
    pub fn bytes(&self) -> u64 {
        match self.atlas() {
            Some(a) => a.budget_bytes(),
            None if self.rays() => 0,
            None => self.lights as u64 * 6 * self.size as u64 * self.size as u64 * 4,
        }
    }

    /// Reject point-light shadow requests the device or the scene's `lights` cannot take,
    /// before allocating.
    pub(crate) fn check(&self, ctx: &Context, lights: usize) -> Result<(), SettingsError> {
        let limits = &ctx.info.limits;
        let device = || ctx.info.name.clone();
        // Directional lights alone may cast shadow rays (`RenderSettings::check_casters` makes
        // sure the scene has some).
        if lights == 0 && self.rays() {
            return Ok(());
        }
        if lights == 0 {
            return Err(SettingsError::ShadowsWithoutLights);
        }
        if self.lights == 0 || (self.lights as usize > lights && !self.all) {
            return Err(SettingsError::ShadowedLights { value: self.lights, lights });
        }
        if let Some(atlas) = self.atlas() {
            return check_atlas(ctx, self, atlas);
        }
        if self.rays() {
            return Ok(());
        }
        let max_cubes = limits.max_image_array_layers / 6;
        if self.lights > max_cubes {
            return Err(SettingsError::TooManyCubes { value: self.lights, max: max_cubes, device: device() });
        }
        let max_size = limits.max_image_dimension_cube.min(MAX_DIMENSION);
        if self.size == 0 || self.size > max_size {
            return Err(SettingsError::OutOfRange { what: Setting::CubeSize, value: self.size, max: max_size });
        }
        if self.bytes() > MAX_OMNI_BYTES {
            return Err(SettingsError::ShadowMemory {
                lights: self.lights,
                size: self.size,
                mib: self.bytes() >> 20,
                max_mib: MAX_OMNI_BYTES >> 20,
            });
        }
        let missing = |feature, instead| SettingsError::MissingFeature { mode: self.mode.name(), feature, device: device(), instead };
        if self.mode == OmniShadowMode::Multiview && !ctx.info.features.multiview {
            return Err(missing("multiview", "layered, direct or copy"));
        }
        if self.mode == OmniShadowMode::Multiview && multiview_depth_is_broken(ctx) {
            return Err(SettingsError::BrokenMultiview { device: device(), driver: ctx.info.driver_info.clone() });
        }
        if self.mode == OmniShadowMode::Layered && !ctx.info.features.shader_output_layer {
            return Err(missing("shaderOutputLayer", "direct or copy"));
        }
        if let OmniShadowMode::Compute { .. } = self.mode {
            check_compute_raster(ctx, self)?;
            // The depths are one storage buffer, as large as the cubes.
            if self.bytes() > limits.max_storage_buffer_range as u64 {
                return Err(SettingsError::ShadowBuffer {
                    lights: self.lights,
                    size: self.size,
                    mib: self.bytes() >> 20,
                    device: device(),
                    max_mib: limits.max_storage_buffer_range as u64 >> 20,
                });
            }
        }
        Ok(())
    }
}

/// Who draws the sun's shadow map (blinn-phong), once, when the scene's objects reach the GPU
/// (docs/DESIGN.md#sun-shadow-map).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SunShadowMode {
    /// A depth-only render pass.
    Graphics,
    /// The compute shadow raster, in one orthographic view (docs/DESIGN.md#compute-shadow-raster).
    Compute,
    /// No map: each point traces a shadow ray toward the sun (docs/DESIGN.md#shadow-rays).
    Rays,
}

impl SunShadowMode {
    pub const ALL: [SunShadowMode; 3] = [SunShadowMode::Graphics, SunShadowMode::Compute, SunShadowMode::Rays];

    pub fn name(self) -> &'static str {
        match self {
            SunShadowMode::Graphics => "graphics",
            SunShadowMode::Compute => "compute",
            SunShadowMode::Rays => "rays",
        }
    }

    pub fn from_name(name: &str) -> Result<SunShadowMode, RenderError> {
        by_name(&SunShadowMode::ALL, SunShadowMode::name, Named::SunShadowMode, name)
    }
}

/// What the shadow settings compile into the lighting pipelines, for a scene with or without
/// directional lights: `OMNI_SHADOWS`, `SHADOW_ATLAS`, `SHADOW_RAYS`, `DIRECTIONAL_RAYS`
/// (shadows/omni_shadow.glsl: the point lights' shadows are maps and the scene has
/// directional lights, which cast theirs by rays) and `SUN_RAYS` (common/blinn_phong.glsl:
/// the sun's shadow is a ray, no map).
pub fn lighting_constants(
    omni: Option<OmniShadowSettings>,
    sun: Option<SunShadowMode>,
    directional_lights: bool,
) -> [(&'static str, u32); 5] {
    let rays = omni.is_some_and(|o| o.rays());
    [
        ("OMNI_SHADOWS", u32::from(omni.is_some())),
        ("SHADOW_ATLAS", u32::from(omni.is_some_and(|o| o.atlas().is_some()))),
        ("SHADOW_RAYS", u32::from(rays)),
        ("DIRECTIONAL_RAYS", u32::from(omni.is_some() && !rays && directional_lights)),
        ("SUN_RAYS", u32::from(sun == Some(SunShadowMode::Rays))),
    ]
}

/// Whether the lighting traces shadow rays with those constants.
pub fn traces_rays(constants: &[(&'static str, u32)]) -> bool {
    constants.iter().any(|&(name, on)| on != 0 && matches!(name, "SHADOW_RAYS" | "DIRECTIONAL_RAYS" | "SUN_RAYS"))
}

/// Most memory the shadow cubes may take, whatever the device has: 16 lights at 2048² are 1.5 GiB.
pub const MAX_OMNI_BYTES: u64 = 4 << 30;

/// Reject shadow-atlas requests the device cannot take, before allocating.
fn check_atlas(ctx: &Context, omni: &OmniShadowSettings, atlas: AtlasSettings) -> Result<(), SettingsError> {
    let device = || ctx.info.name.clone();
    if omni.lights > MAX_SHADOWED_LIGHTS {
        return Err(SettingsError::TooManyShadowed { value: omni.lights, max: MAX_SHADOWED_LIGHTS });
    }
    let memory_mib = ctx.device_local_bytes() >> 20;
    if atlas.budget_mib == 0 || atlas.budget_mib as u64 > memory_mib {
        return Err(SettingsError::ShadowBudget { mib: atlas.budget_mib, max_mib: memory_mib, device: device() });
    }
    if let Some(size) = atlas.fixed_size {
        let (min, max) = (ml_cpu::shadow_atlas::MIN_FACE, ml_cpu::shadow_atlas::MAX_FACE);
        if !size.is_power_of_two() || !(min..=max).contains(&size) {
            return Err(SettingsError::AtlasFaceSize { value: size, min, max });
        }
    }
    check_compute_raster(ctx, omni)
}

/// The compute shadow raster (the compute and atlas modes) needs 64-bit integers: its edge
/// functions are 64-bit.
fn check_compute_raster(ctx: &Context, omni: &OmniShadowSettings) -> Result<(), SettingsError> {
    if !ctx.info.features.buffer_int64_atomics {
        let device = ctx.info.name.clone();
        return Err(SettingsError::MissingFeature {
            mode: omni.mode.name(),
            feature: "shaderInt64",
            device,
            instead: "layered, direct or copy",
        });
    }
    Ok(())
}

/// Whether the driver is one that renders a depth-only multiview pass wrong: Mesa's
/// lavapipe 22.3 (Debian 12's) draws all six views into layer 0 — found by the shadow-cube
/// debug view; the same pass on the H100 matches `direct` exactly (docs/BENCHMARKS.md).
/// Later Mesa releases are not known to be fixed, so every lavapipe refuses it.
pub fn multiview_depth_is_broken(ctx: &Context) -> bool {
    ctx.info.name.starts_with("llvmpipe")
}
