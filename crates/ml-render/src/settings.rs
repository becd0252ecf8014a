//! What a render is asked to do, checked against the device before anything is allocated.

pub use crate::antialiasing::Antialiasing;
use crate::background::Background;
pub use crate::debug_view::{DebugView, ViewNeed};
use crate::error::{by_name, or_list, Named, RenderError, Setting, SettingsError};
pub use crate::exposure::{parse_exposure, Exposure, MAX_EXPOSURE_EV};
use crate::scene::SceneConfig;
pub use crate::shading::Shading;
pub use crate::shadows::shadow_settings::{
    multiview_depth_is_broken, AtlasSettings, OmniShadowMode, OmniShadowSettings, SunShadowMode, MAX_OMNI_BYTES, MAX_SHADOWED_LIGHTS,
};
use crate::shadows::stores::ShadowConfig;
pub use crate::targets::MAX_DIMENSION;
use crate::targets::{multisampled_images, Output};
pub use crate::technique::{
    missing_meshlet_feature, missing_raster_feature, Geometry, LargeTriangles, LightAssignment, LightingStage, Raster, Technique,
};
pub use crate::transparency::TransparencySettings;
use ml_cpu::cluster::ClusterDims;
pub use ml_cpu::shading_model::ShadingModel;
use ml_vk::{vk, Context};

impl ViewNeed {
    /// Whether the sun's shadow mode draws a map.
    pub fn sun_map(mode: SunShadowMode) -> bool {
        mode != SunShadowMode::Rays
    }

    /// Whether `settings` have it.
    pub fn holds(&self, s: &RenderSettings) -> bool {
        match *self {
            ViewNeed::Technique { holds, .. } => holds(s.technique),
            ViewNeed::OmniShadow { modes, .. } => s.omni.is_some_and(|o| modes.contains(&o.mode.name())),
            ViewNeed::Shading { model, .. } => s.shading == model,
            ViewNeed::SunMap => ViewNeed::sun_map(s.sun_shadow),
            ViewNeed::TransparentObjects => s.transparency.is_some(),
            ViewNeed::SampleBuffer => s.raster.fills_buffer(s.antialiasing),
        }
    }

    /// What it needs, in the options that give it.
    pub fn needs(&self) -> String {
        match *self {
            ViewNeed::Technique { what, holds } => {
                format!("--technique {} ({what})", or_list(Technique::ALL.into_iter().filter(|&t| holds(t)).map(Technique::name)))
            }
            ViewNeed::OmniShadow { what, modes } => format!("{what} (--omni-shadow {})", or_list(modes.iter().copied())),
            ViewNeed::Shading { model, what } => format!("{what} (--shading {})", model.name()),
            ViewNeed::SunMap => {
                let modes = SunShadowMode::ALL.into_iter().filter(|&m| ViewNeed::sun_map(m)).map(SunShadowMode::name);
                format!("a sun's shadow map (--sun-shadow {})", or_list(modes))
            }
            ViewNeed::TransparentObjects => {
                "transparent objects (alphaMode BLEND in a glTF file, --transparent-objects or --glass-layers)".into()
            }
            ViewNeed::SampleBuffer => "the 64-bit depth-and-id buffer (--raster compute or hybrid, or --aa)".into(),
        }
    }

    /// What `settings` have instead, where it does not hold.
    fn instead(&self, s: &RenderSettings) -> String {
        match self {
            ViewNeed::Technique { .. } => s.technique.name().to_owned(),
            ViewNeed::OmniShadow { .. } => format!("--omni-shadow {}", s.omni.map_or("off", |o| o.mode.name())),
            ViewNeed::Shading { .. } => format!("the {} shading model", s.shading.name()),
            ViewNeed::SunMap => format!("--sun-shadow {}", s.sun_shadow.name()),
            ViewNeed::TransparentObjects => "a scene without transparent objects".into(),
            ViewNeed::SampleBuffer => "--raster hardware with --aa off".into(),
        }
    }
}

/// Whether the light grid's build lists only the lights near the frame's surfaces, after a
/// pass over the pixels that marks the cells their points walk (docs/DESIGN.md#the-light-grid),
/// or every light. The pass costs per pixel and listing a light costs per light: the marks
/// pay where the lights are more than about a third of the pixels (measured on the H100).
/// With coverage samples the pass reads each and marks each surface of a pixel: at 8 samples
/// it costs 3.7 times as much (H200, 1080p: 0.119 ms against 0.032), so it pays only with
/// more lights — a pixel of N samples counts as N/2.
/// The same lights light every pixel either way.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightGridMarks {
    /// Marks where the lights are more than a third of the pixels (those with N coverage
    /// samples counted N/2 times).
    Auto,
    On,
    Off,
}

impl LightGridMarks {
    pub const ALL: [LightGridMarks; 3] = [LightGridMarks::Auto, LightGridMarks::On, LightGridMarks::Off];
    pub const NAMES: [&'static str; 3] = ["auto", "on", "off"];

    pub fn name(self) -> &'static str {
        LightGridMarks::NAMES[self as usize]
    }

    pub fn from_name(name: &str) -> Result<LightGridMarks, RenderError> {
        by_name(&LightGridMarks::ALL, LightGridMarks::name, Named::LightGridMarks, name)
    }

    /// Whether a frame of `width`×`height` pixels, `antialiasing`'s samples each, with
    /// `lights` lights marks.
    pub fn resolve(self, lights: u64, width: u32, height: u32, antialiasing: Antialiasing) -> bool {
        let weight = u64::from((antialiasing.samples() / 2).max(1));
        match self {
            LightGridMarks::On => true,
            LightGridMarks::Off => false,
            LightGridMarks::Auto => lights.saturating_mul(3) > u64::from(width) * u64::from(height) * weight,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    pub technique: Technique,
    pub shading: ShadingModel,
    /// Cluster grid of the clustered techniques.
    pub clusters: ClusterDims,
    pub debug_view: DebugView,
    /// Point-light shadow cubes (None: point lights cast no shadows).
    pub omni: Option<OmniShadowSettings>,
    /// Who draws the sun's shadow map (blinn-phong).
    pub sun_shadow: SunShadowMode,
    pub width: u32,
    pub height: u32,
    /// Frames to render; the image is the last one's, timings are averaged over all.
    pub frames: u32,
    /// Fixed animation clock; None advances it by 1/60 s per frame from 0 (deterministic).
    pub time: Option<f32>,
    /// GPU culling of the meshlet techniques (off: every meshlet drawn, for comparisons).
    pub culling: bool,
    /// Who draws the visibility buffer (visibility only).
    pub raster: Raster,
    /// What lit colour is multiplied by before tone map and gamma.
    pub exposure: Exposure,
    /// Transparent (BLEND) objects blended in per-pixel layers, with this budget; None: drawn
    /// as masks at alpha one half (and so where the scene has none).
    pub transparency: Option<TransparencySettings>,
    /// Count the lights tested and reaching per pixel after the lighting (`LightStats`; the
    /// compute-lit techniques, deferred-compute and visibility).
    pub light_stats: bool,
    /// The light grid marks the cells near the surfaces before its build (the techniques
    /// that know their surfaces before their lighting: deferred-compute, visibility).
    pub light_grid_marks: bool,
    /// Coverage samples per pixel (the visibility technique's compute raster).
    pub antialiasing: Antialiasing,
    /// Highlights under normal maps widened by the normals' spread (surface.glsl).
    pub specular_aa: bool,
    /// What pixels no surface covers show.
    pub background: Background,
}

/// The seed's timer runs at a quarter of real time (`timerSpeed *= 0.25`).
pub const TIMER_SPEED: f32 = 0.25;
pub const FRAME_SECONDS: f32 = 1.0 / 60.0;

impl RenderSettings {
    /// What the scene's GPU resources are made for: the blinn-phong model's maps, and whether
    /// some pass draws the scene's meshlets (the visibility technique, the compute shadow
    /// rasters).
    pub fn scene_config(&self) -> SceneConfig {
        let ShadowConfig { sun, omni } = self.shadow_config();
        let omni_compute = omni.is_some_and(|o| matches!(o.mode, OmniShadowMode::Compute { .. } | OmniShadowMode::Atlas(_)));
        let meshlets = self.technique.geometry() == Geometry::Meshlets || omni_compute || sun == Some(SunShadowMode::Compute);
        SceneConfig { material_maps: self.shading == ShadingModel::BlinnPhong, meshlets }
    }

    /// What the shadow stores are made for: the sun's map (blinn-phong), the point lights'.
    pub fn shadow_config(&self) -> ShadowConfig {
        ShadowConfig { sun: (self.shading == ShadingModel::BlinnPhong).then_some(self.sun_shadow), omni: self.omni }
    }

    /// Defaults for everything but technique and size: the seed model, 16×9×24 clusters, one
    /// frame at time 0.
    pub fn new(technique: Technique, width: u32, height: u32) -> RenderSettings {
        RenderSettings {
            technique,
            shading: ShadingModel::Seed,
            clusters: ClusterDims::DEFAULT,
            debug_view: DebugView::NONE,
            omni: None,
            sun_shadow: SunShadowMode::Graphics,
            width,
            height,
            frames: 1,
            time: Some(0.0),
            culling: true,
            raster: Raster::Hardware,
            exposure: Exposure::Ev(0.0),
            transparency: None,
            light_stats: false,
            light_grid_marks: true,
            antialiasing: Antialiasing::Off,
            specular_aa: true,
            background: Background::Colour,
        }
    }

    /// The image's width over its height.
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// The debug view's first need the settings lack.
    fn check_view(&self) -> Result<(), SettingsError> {
        match self.debug_view.needs().iter().find(|need| !need.holds(self)) {
            Some(need) => Err(SettingsError::ViewNeeds { view: self.debug_view.name(), needs: need.needs(), instead: need.instead(self) }),
            None => Ok(()),
        }
    }

    /// Whether the exposure-meter pass runs: auto exposure, on the shaded image (a debug view
    /// shows its values as they are).
    pub fn meters_exposure(&self) -> bool {
        self.exposure == Exposure::Auto && self.debug_view.is_none()
    }

    /// Whether the transparent layers are built and blended: transparency on, and the image
    /// shaded (or the layer view); a surface debug view shows the opaque surfaces only.
    pub fn blends_layers(&self) -> bool {
        self.transparency.is_some() && self.debug_view.shows_layers()
    }

    /// Animation clock of frame `i`.
    pub fn clock(&self, i: u32) -> f32 {
        self.time.unwrap_or(i as f32 * FRAME_SECONDS * TIMER_SPEED)
    }

    /// Reject shadow rays where no light, of `lights` point and `directional` directional
    /// ones, casts them (`check` leaves a scene without point lights to this).
    pub fn check_casters(&self, lights: usize, directional: usize) -> Result<(), SettingsError> {
        if self.omni.is_some_and(|o| o.rays()) && lights == 0 && directional == 0 {
            return Err(SettingsError::ShadowsWithoutLights);
        }
        Ok(())
    }

    /// Reject sizes and counts the device (or common sense) cannot take, before allocating.
    pub fn check(&self, ctx: &Context, lights: usize) -> Result<(), RenderError> {
        let limits = &ctx.info.limits;
        let device = || ctx.info.name.clone();
        // Every lighting shader declares the point-light shadow cubes (textures.glsl).
        if !ctx.info.features.image_cube_array {
            return Err(SettingsError::NoCubeArrays { device: device() }.into());
        }
        let max = limits.max_image_dimension2_d.min(MAX_DIMENSION);
        for (what, value) in [(Setting::Width, self.width), (Setting::Height, self.height)] {
            if value == 0 || value > max {
                return Err(SettingsError::OutOfRange { what, value, max }.into());
            }
        }
        self.check_view()?;
        if self.light_stats && self.technique.lighting_stage() != LightingStage::Compute {
            return Err(SettingsError::LightStatsNeedCompute { technique: self.technique.name() }.into());
        }
        check_antialiasing(self, ctx)?;
        if self.technique.geometry() == Geometry::Meshlets {
            if let Some(feature) = missing_meshlet_feature(&ctx.info.features) {
                return Err(SettingsError::TechniqueFeature { technique: self.technique.name(), feature, device: device() }.into());
            }
        }
        if let Raster::Compute { split, .. } = self.raster {
            if self.technique.geometry() != Geometry::Meshlets {
                return Err(SettingsError::RasterNeedsVisibility { technique: self.technique.name() }.into());
            }
            if let Some(feature) = missing_raster_feature(self.raster, &ctx.info.features) {
                return Err(SettingsError::RasterFeature { raster: self.raster.name(), feature, device: device() }.into());
            }
            if split == 0 || split > Raster::MAX_SPLIT {
                return Err(SettingsError::OutOfRange { what: Setting::RasterSplit, value: split, max: Raster::MAX_SPLIT }.into());
            }
            // Its depth-and-id buffer, 8 bytes a sample, is one storage buffer.
            let bytes = self.antialiasing.buffer_bytes(self.width, self.height);
            if bytes > limits.max_storage_buffer_range as u64 {
                let (width, height, max) = (self.width, self.height, limits.max_storage_buffer_range);
                return Err(SettingsError::RasterBuffer { width, height, bytes, device: device(), max }.into());
            }
            // So is each of the large-triangle lists (the triangles' the larger).
            if let Some(bins) = self.raster.bin_list() {
                let bytes = bins as u64 * std::mem::size_of::<ml_cpu::gpu_types::LargeTriangle>() as u64;
                if bytes > limits.max_storage_buffer_range as u64 {
                    let max = limits.max_storage_buffer_range;
                    return Err(SettingsError::BinList { bins, bytes, device: device(), max }.into());
                }
            }
        }
        if let Some(omni) = &self.omni {
            omni.check(ctx, lights)?;
        }
        if let Some(t) = &self.transparency {
            t.check(ctx, self.width, self.height)?;
        }
        if self.sun_shadow == SunShadowMode::Compute && self.shading == ShadingModel::BlinnPhong {
            let features = &ctx.info.features;
            let depth = ctx.format_supports(
                vk::Format::D32_SFLOAT,
                vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT | vk::FormatFeatureFlags::SAMPLED_IMAGE,
            );
            let missing = [(features.buffer_int64_atomics, "shaderInt64"), (depth, "a sampled D32_SFLOAT depth format")];
            if let Some((_, feature)) = missing.into_iter().find(|(has, _)| !has) {
                return Err(SettingsError::SunShadowFeature { feature, device: device() }.into());
            }
        }
        if self.frames == 0 {
            return Err(SettingsError::NoFrames.into());
        }
        if let Some(t) = self.time.filter(|t| !t.is_finite()) {
            return Err(SettingsError::Time(t).into());
        }
        let bytes = lights as u64 * std::mem::size_of::<ml_cpu::gpu_types::PointLight>() as u64;
        if bytes > limits.max_storage_buffer_range as u64 {
            return Err(SettingsError::LightBuffer { lights, bytes, device: device(), max: limits.max_storage_buffer_range }.into());
        }
        Ok(())
    }
}

/// The settings a command asks for, before the scene is known: the render's own, but for what
/// the scene settles — its shading model (`settings.shading` is replaced), the cluster grid
/// its light count may choose, whether it has transparent objects to blend, whether the light
/// grid marks its cells (auto: by its lights per pixel) and how many lights cast shadows
/// (`--shadowed-lights all`: those in view).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SettingsRequest {
    /// Everything else, as it will render; its `clusters`, `transparency` and
    /// `light_grid_marks` are replaced by `for_scene` from the fields below.
    pub settings: RenderSettings,
    /// Cluster grid; None: `ClusterDims::for_lights` for the scene's lights at this size.
    pub clusters: Option<ClusterDims>,
    /// How transparent objects are blended, where the scene has any.
    pub transparency: TransparencySettings,
    /// Whether the light grid marks the cells near the surfaces first.
    pub light_grid_marks: LightGridMarks,
    /// What pixels without a surface show; None: the scene's environment where it asks to be
    /// shown (and lights a pbr model), else the colour.
    pub background: Option<Background>,
}

impl SettingsRequest {
    /// `settings` asked for as they are, the rest at its defaults: the scene's grid, its
    /// transparent objects blended within the default budget, the marks decided by its lights.
    pub fn new(settings: RenderSettings) -> SettingsRequest {
        SettingsRequest {
            settings,
            clusters: None,
            transparency: TransparencySettings::default(),
            light_grid_marks: LightGridMarks::Auto,
            background: None,
        }
    }

    /// Whether settings `s` for a scene of `lights` lights mark the light grid: for_scene's
    /// choice, made again where the sample count is settled after it.
    pub fn marks_light_grid(&self, lights: usize, s: &RenderSettings) -> bool {
        self.light_grid_marks.resolve(lights as u64, s.width, s.height, s.antialiasing)
    }

    /// The settings that render `scene` with `shading` (the model its request resolved to).
    pub fn for_scene(&self, scene: &ml_cpu::scene::Scene, shading: ShadingModel) -> RenderSettings {
        let s = &self.settings;
        RenderSettings {
            shading,
            clusters: self.clusters.unwrap_or_else(|| ClusterDims::for_lights(scene.lights.len(), s.width, s.height)),
            omni: s.omni.map(|o| OmniShadowSettings { lights: shadowed_count(&o, scene, (s.width, s.height)), ..o }),
            transparency: scene.has_transparent_objects().then_some(self.transparency),
            light_grid_marks: self.marks_light_grid(scene.lights.len(), s),
            background: self.background.unwrap_or(Background::asked_by(scene, shading)),
            ..*s
        }
    }
}

/// How many lights cast shadows: `--shadowed-lights all` counts those that reach the view
/// (at least one slot, so that a view without any still renders); with shadow rays, every
/// light.
fn shadowed_count(omni: &OmniShadowSettings, scene: &ml_cpu::scene::Scene, (width, height): (u32, u32)) -> u32 {
    if !omni.all {
        return omni.lights;
    }
    if omni.rays() {
        return (scene.lights.len() as u32).max(1);
    }
    let aspect = width.max(1) as f32 / height.max(1) as f32;
    let seen = ml_cpu::omni_shadow::lights_in_view(&scene.lights, &scene.camera, aspect, scene.light_motion, MAX_SHADOWED_LIGHTS as usize);
    (seen.len() as u32).max(1)
}

/// Whether transparent layers are blended with `antialiasing` in `technique`: without samples
/// in every technique; with them in the visibility technique, which keeps each opaque
/// surface's colour per sample (up to LAYER_MAX_SAMPLES).
pub fn layers_take(technique: Technique, antialiasing: Antialiasing) -> bool {
    let max = crate::transparency::LAYER_MAX_SAMPLES;
    antialiasing == Antialiasing::Off || (technique == Technique::Visibility && antialiasing.samples() <= max)
}

/// Refuse `--aa` where `s` cannot keep samples (in one line: the technique, the raster, the
/// transparent layers, the sample counts the device offers for what the samples are drawn
/// into).
fn check_antialiasing(s: &RenderSettings, ctx: &Context) -> Result<(), RenderError> {
    if s.antialiasing == Antialiasing::Off {
        return Ok(());
    }
    let samples = s.antialiasing.name();
    // The light counts read the opaque depth: the 64-bit buffer (visibility) or a
    // single-sampled depth target.
    if s.light_stats && s.technique.geometry() == Geometry::Meshes {
        return Err(SettingsError::LightStatsWithSamples { samples, technique: s.technique.name() }.into());
    }
    // The layers' nodes keep at most LAYER_MAX_SAMPLES samples' coverage, and only the
    // visibility technique keeps its surfaces' colours per sample for their blend.
    let max = crate::transparency::LAYER_MAX_SAMPLES;
    if s.blends_layers() && !layers_take(s.technique, s.antialiasing) {
        return Err(SettingsError::AntialiasingWithLayers { samples, technique: s.technique.name(), max }.into());
    }
    // The visibility technique keeps its samples in the 64-bit buffer.
    let int64 = ctx.info.features.buffer_int64_atomics;
    if s.technique == Technique::Visibility && !int64 {
        let feature = "shaderInt64 (the samples' 64-bit buffer)";
        return Err(SettingsError::AntialiasingFeature { samples, feature, device: ctx.info.name.clone() }.into());
    }
    // The hardware raster's samples gathered into that buffer: one storage buffer (the
    // compute rasters' is checked with them).
    let max = ctx.info.limits.max_storage_buffer_range;
    let bytes = s.antialiasing.buffer_bytes(s.width, s.height);
    if s.technique == Technique::Visibility && s.raster == Raster::Hardware && bytes > u64::from(max) {
        let (width, height, device) = (s.width, s.height, ctx.info.name.clone());
        return Err(SettingsError::RasterBuffer { width, height, bytes, device, max }.into());
    }
    // What the samples are drawn into (the hybrid raster's large triangles: a draw without
    // attachments), and the sample counts the device offers for each.
    let mut drawn: Vec<(String, vk::SampleCountFlags)> = Vec::new();
    let output = Output::of(s.technique);
    let depth_format = crate::targets::depth_format(ctx, output)?;
    let hybrid = s.raster != Raster::Hardware && s.raster.bin_list().is_none();
    for (image, format, usage) in multisampled_images(output, s.raster, depth_format) {
        drawn.push((format!("{}'s {image} ({format:?})", s.technique.name()), ctx.image_sample_counts(format, usage)));
    }
    if s.technique == Technique::Visibility && hybrid {
        let offered = ctx.info.limits.framebuffer_no_attachments_sample_counts;
        drawn.push(("the hybrid raster's large triangles (a draw without attachments)".to_owned(), offered));
    }
    for (what, offered) in drawn {
        if !offered.contains(s.antialiasing.sample_count()) {
            let offered: Vec<String> =
                Antialiasing::ALL.iter().filter(|a| offered.contains(a.sample_count())).map(|a| a.samples().to_string()).collect();
            let offered = match offered.split_last() {
                Some((last, [])) => last.clone(),
                Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
                None => "no".to_owned(),
            };
            return Err(SettingsError::AntialiasingSamples { samples, what, device: ctx.info.name.clone(), offered }.into());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{Antialiasing, LightGridMarks};

    #[test]
    fn auto_marks_where_the_lights_are_more_than_a_third_of_the_pixels() {
        let off = Antialiasing::Off;
        // 1920×1080 = 2,073,600 pixels: a third is 691,200.
        assert!(!LightGridMarks::Auto.resolve(691_200, 1920, 1080, off));
        assert!(LightGridMarks::Auto.resolve(691_201, 1920, 1080, off));
        assert!(!LightGridMarks::Auto.resolve(1 << 20, 3840, 2160, off));
        assert!(LightGridMarks::Auto.resolve(1 << 22, 3840, 2160, off));
        // Pixels of 8 samples count 4 times: 1M lights at 1080p no longer mark, 4M still do
        // (measured on the H200: 0.957 ms a frame against 1.028, and 1.085 against 1.098).
        assert!(LightGridMarks::Auto.resolve(1 << 20, 1920, 1080, off));
        assert!(!LightGridMarks::Auto.resolve(1 << 20, 1920, 1080, Antialiasing::X8));
        assert!(!LightGridMarks::Auto.resolve(1 << 20, 1920, 1080, Antialiasing::X4));
        assert!(LightGridMarks::Auto.resolve(1 << 22, 1920, 1080, Antialiasing::X8));
        assert!(!LightGridMarks::Auto.resolve(1 << 22, 3840, 2160, Antialiasing::X8));
        assert!(LightGridMarks::On.resolve(0, 1920, 1080, Antialiasing::X16));
        assert!(!LightGridMarks::Off.resolve(u64::MAX, 1, 1, off));
        for marks in LightGridMarks::ALL {
            assert_eq!(LightGridMarks::from_name(marks.name()).ok(), Some(marks));
        }
        assert!(LightGridMarks::from_name("sometimes").is_err());
    }
}
