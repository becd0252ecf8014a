//! What a render is asked to do, checked against the device before anything is allocated.

use crate::error::{Named, RenderError, Setting, SettingsError};
use ml_cpu::cluster::ClusterDims;
pub use ml_cpu::shading_model::ShadingModel;
use ml_vk::{vk, Context};

/// Lighting techniques (docs/DESIGN.md#techniques-are-two-choices). Each must give the same image as `Forward`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Technique {
    /// Brute force: every fragment loops over every light.
    Forward,
    /// Cluster grid with lights assigned on the CPU every frame.
    ClusteredCpu,
    /// Cluster grid built by compute shaders every frame; lights animated on the GPU.
    ClusteredGpu,
    /// One render pass, G-buffer subpass → lighting subpass (input attachments),
    /// every light per pixel, into an HDR target; then a tone-map pass.
    Deferred,
    /// `Deferred` with the lighting subpass looping over its cluster's lights (CPU-assigned).
    DeferredClustered,
    /// clustered-gpu's lists, with the lighting as a compute pass over a G-buffer.
    DeferredCompute,
    /// GPU-driven: meshlets culled on the GPU (frustum, back-face cones, occlusion in two
    /// phases), drawn indirectly into a visibility buffer, lit by a compute pass through
    /// clustered-gpu's lists.
    Visibility,
}

impl Technique {
    pub const ALL: [Technique; 7] = [
        Technique::Forward,
        Technique::ClusteredCpu,
        Technique::ClusteredGpu,
        Technique::Deferred,
        Technique::DeferredClustered,
        Technique::DeferredCompute,
        Technique::Visibility,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Technique::Forward => "forward",
            Technique::ClusteredCpu => "clustered-cpu",
            Technique::ClusteredGpu => "clustered-gpu",
            Technique::Deferred => "deferred",
            Technique::DeferredClustered => "deferred-clustered",
            Technique::DeferredCompute => "deferred-compute",
            Technique::Visibility => "visibility",
        }
    }

    /// Where lights are assigned to clusters (docs/DESIGN.md#techniques-are-two-choices).
    pub fn assignment(self) -> LightAssignment {
        match self {
            Technique::Forward | Technique::Deferred => LightAssignment::None,
            Technique::ClusteredCpu | Technique::DeferredClustered => LightAssignment::Cpu,
            Technique::ClusteredGpu | Technique::DeferredCompute | Technique::Visibility => LightAssignment::Gpu,
        }
    }

    /// Where the lighting runs.
    pub fn lighting_stage(self) -> LightingStage {
        match self {
            Technique::Forward | Technique::ClusteredCpu | Technique::ClusteredGpu => LightingStage::Forward,
            Technique::Deferred | Technique::DeferredClustered => LightingStage::Subpass,
            Technique::DeferredCompute | Technique::Visibility => LightingStage::Compute,
        }
    }

    /// How the geometry reaches the pixels.
    pub fn geometry(self) -> Geometry {
        match self {
            Technique::Visibility => Geometry::Meshlets,
            _ => Geometry::Meshes,
        }
    }

    pub fn is_clustered(self) -> bool {
        self.assignment() != LightAssignment::None
    }

    /// Whether it draws the cluster-heat debug view: the clustered forward fragment shader
    /// does.
    pub fn draws_cluster_heat(self) -> bool {
        self.is_clustered() && self.lighting_stage() == LightingStage::Forward
    }

    /// Whether the lighting runs in the second subpass of the raster pass.
    pub fn lights_in_subpass(self) -> bool {
        self.lighting_stage() == LightingStage::Subpass
    }

    /// Whether the lighting runs as a compute pass over a G-buffer.
    pub fn lights_in_compute(self) -> bool {
        self.lighting_stage() == LightingStage::Compute
    }

    pub fn from_name(name: &str) -> Result<Technique, RenderError> {
        by_name(&Technique::ALL, Technique::name, Named::Technique, name)
    }
}

/// The one of `all` whose name (`name_of`) is `name`; else the error that lists the names.
fn by_name<T: Copy>(all: &[T], name_of: fn(T) -> &'static str, kind: Named, name: &str) -> Result<T, RenderError> {
    all.iter().copied().find(|&v| name_of(v) == name).ok_or_else(|| {
        let expected = all.iter().map(|&v| name_of(v)).collect::<Vec<_>>().join(", ");
        RenderError::UnknownName { kind, name: name.to_owned(), expected }
    })
}

/// Where lights are assigned to clusters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightAssignment {
    /// Nowhere: every pixel loops over every light.
    None,
    /// On the CPU every frame, uploaded into the frame's lists.
    Cpu,
    /// By compute shaders every frame (which also animate the lights).
    Gpu,
}

/// Where the lighting runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightingStage {
    /// In the fragment shader that draws the objects.
    Forward,
    /// In the second subpass of the deferred render pass, over the G-buffer.
    Subpass,
    /// In a compute pass over the G-buffer.
    Compute,
}

/// How the geometry reaches the pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Geometry {
    /// Every object's mesh drawn with one draw call from the CPU, every frame.
    Meshes,
    /// Meshlets culled on the GPU and drawn by indirect draws into a visibility buffer.
    Meshlets,
}

/// What a lighting pipeline is compiled for: the model, whether point lights cast shadows,
/// whether objects have textures of their own and whether there are spot lights
/// (specialization constants, so each pipeline carries only what it runs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shading {
    pub model: ShadingModel,
    pub omni_shadows: bool,
    /// The point lights' shadows are in the shadow atlas (else in the cube array).
    pub shadow_atlas: bool,
    pub object_textures: bool,
    pub spot_lights: bool,
}

impl Shading {
    /// The specialization constants (name, value) of a pipeline that reads surfaces without
    /// lighting them (the G-buffer's): `MODEL_BLINN_PHONG`, `MODEL_PBR` and `OBJECT_TEXTURES`
    /// (common/shading_model.glsl).
    pub fn surface_constants(self) -> [(&'static str, u32); 3] {
        [
            ("MODEL_BLINN_PHONG", u32::from(self.model == ShadingModel::BlinnPhong)),
            ("MODEL_PBR", u32::from(self.model == ShadingModel::Pbr)),
            ("OBJECT_TEXTURES", u32::from(self.object_textures)),
        ]
    }

    /// The specialization constants (name, value) of a lighting pipeline: the surface's,
    /// `OMNI_SHADOWS` and `SHADOW_ATLAS` (shadows/omni_shadow.glsl) and `SPOT_LIGHTS`
    /// (common/lighting.glsl).
    pub fn lighting_constants(self) -> [(&'static str, u32); 6] {
        let [model_a, model_b, textures] = self.surface_constants();
        [
            model_a,
            model_b,
            textures,
            ("OMNI_SHADOWS", u32::from(self.omni_shadows)),
            ("SHADOW_ATLAS", u32::from(self.shadow_atlas)),
            ("SPOT_LIGHTS", u32::from(self.spot_lights)),
        ]
    }
}

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

    pub const ALL: [OmniShadowMode; 6] = [
        OmniShadowMode::Copy,
        OmniShadowMode::Direct,
        OmniShadowMode::Multiview,
        OmniShadowMode::Layered,
        OmniShadowMode::COMPUTE,
        OmniShadowMode::Atlas(AtlasSettings::DEFAULT),
    ];

    pub fn name(self) -> &'static str {
        match self {
            OmniShadowMode::Copy => "copy",
            OmniShadowMode::Direct => "direct",
            OmniShadowMode::Multiview => "multiview",
            OmniShadowMode::Layered => "layered",
            OmniShadowMode::Compute { .. } => "compute",
            OmniShadowMode::Atlas(_) => "atlas",
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
    /// `all`, the lights that reach the view (SettingsRequest::for_scene counts them).
    pub lights: u32,
    /// Shadow every light that reaches the view (at most MAX_SHADOWED_LIGHTS), not the
    /// `lights` strongest.
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

    /// Bytes of the cube array (32-bit depth; the shadow atlas's are its budget).
    pub fn bytes(&self) -> u64 {
        match self.atlas() {
            Some(a) => a.budget_bytes(),
            None => self.lights as u64 * 6 * self.size as u64 * self.size as u64 * 4,
        }
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
}

impl SunShadowMode {
    pub const ALL: [SunShadowMode; 2] = [SunShadowMode::Graphics, SunShadowMode::Compute];

    pub fn name(self) -> &'static str {
        match self {
            SunShadowMode::Graphics => "graphics",
            SunShadowMode::Compute => "compute",
        }
    }

    pub fn from_name(name: &str) -> Result<SunShadowMode, RenderError> {
        by_name(&SunShadowMode::ALL, SunShadowMode::name, Named::SunShadowMode, name)
    }
}

/// Who draws the visibility buffer (technique visibility; docs/DESIGN.md#compute-raster).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Raster {
    /// The graphics pipeline: each culling phase's triangles in one indexed draw.
    Hardware,
    /// A compute shader for every triangle whose bounding box is at most `split` pixels a side
    /// and which lies wholly beyond the near plane; the others — large ones, and those
    /// crossing the near plane — drawn into the same 64-bit buffer as `large` says.
    Compute { split: u32, large: LargeTriangles },
}

/// Who draws the compute raster's large triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LargeTriangles {
    /// The hardware, in each phase's indexed draw (`--raster hybrid`).
    Hardware,
    /// Compute too (`--raster compute`): clipped once, and drawn by a work group per
    /// 64×64-pixel bin of their box. `bin_list`: large triangles, and bins, the lists hold per
    /// culling phase; past them the thread that found a triangle draws it alone.
    Bins { bin_list: u32 },
}

impl Raster {
    /// The compute raster's default split: triangles up to this many pixels a side are drawn
    /// in compute (measured: docs/BENCHMARKS.md).
    pub const DEFAULT_SPLIT: u32 = 16;
    /// Its largest: the edge functions of a 64-pixel box at 1/256 pixel stay in 32 bits.
    pub const MAX_SPLIT: u32 = 64;
    /// The lists' default size: 2^16 large triangles and bins (7.5 MiB per frame in flight),
    /// the bins of 32 screens of 3840×2160.
    pub const DEFAULT_BIN_LIST: u32 = 1 << 16;

    /// The compute raster (large triangles too) with `split`.
    pub fn compute(split: u32) -> Raster {
        Raster::Compute { split, large: LargeTriangles::Bins { bin_list: Raster::DEFAULT_BIN_LIST } }
    }

    /// The hybrid raster (large triangles by the hardware) with `split`.
    pub fn hybrid(split: u32) -> Raster {
        Raster::Compute { split, large: LargeTriangles::Hardware }
    }

    pub fn name(self) -> &'static str {
        match self {
            Raster::Hardware => "hardware",
            Raster::Compute { large: LargeTriangles::Hardware, .. } => "hybrid",
            Raster::Compute { large: LargeTriangles::Bins { .. }, .. } => "compute",
        }
    }

    /// The rasteriser `name` names (`hardware`, `hybrid`, `compute`), those in compute with
    /// `split`.
    pub fn from_name(name: &str, split: u32) -> Result<Raster, RenderError> {
        by_name(&[Raster::Hardware, Raster::hybrid(split), Raster::compute(split)], Raster::name, Named::Raster, name)
    }

    /// The largest triangle drawn in compute by one thread (0: none).
    pub fn split(self) -> u32 {
        match self {
            Raster::Hardware => 0,
            Raster::Compute { split, .. } => split,
        }
    }

    /// The large triangles' bin list's size, where they are drawn in compute.
    pub fn bin_list(self) -> Option<u32> {
        match self {
            Raster::Compute { large: LargeTriangles::Bins { bin_list }, .. } => Some(bin_list),
            _ => None,
        }
    }
}

/// The first device feature `raster` needs that `features` lacks, if any.
pub fn missing_raster_feature(raster: Raster, features: &ml_vk::OptionalFeatures) -> Option<&'static str> {
    let Raster::Compute { large, .. } = raster else {
        return None;
    };
    let atomics = (features.buffer_int64_atomics, "shaderInt64 and shaderBufferInt64Atomics (64-bit integers and atomic min on buffers)");
    let fragment = (
        features.fragment_stores_and_atomics || large != LargeTriangles::Hardware,
        "fragmentStoresAndAtomics (the large triangles' fragments write the same buffer)",
    );
    [atomics, fragment].into_iter().find_map(|(has, feature)| (!has).then_some(feature))
}

/// Most memory the shadow cubes may take, whatever the device has: 16 lights at 2048² are 1.5 GiB.
pub const MAX_OMNI_BYTES: u64 = 4 << 30;

/// What the image shows instead of the shaded scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DebugView {
    None,
    /// Lights per cluster as a heat map (clustered forward techniques).
    ClusterHeat,
    /// The G-buffer's channels (any technique: the values it shades with): albedo (texture
    /// included), normal·0.5 + 0.5, (roughness, metallic, 0).
    GBufferAlbedo,
    GBufferNormal,
    GBufferMaterial,
    /// View depth, ln(depth/near)/ln(far/near) in grey.
    Depth,
    /// The sun's shadow map over the whole image (blinn-phong).
    ShadowMap,
    /// The six faces of the first shadowed point light's cube, unfolded as a cross.
    ShadowCube,
    /// The shadow atlas, every block of it, fitted to the image (--omni-shadow atlas).
    ShadowAtlas,
    /// A colour per meshlet instance (visibility).
    Meshlets,
    /// A colour per triangle (visibility).
    Triangles,
    /// Which surfaces alpha masks cut: opaque grey, masked green, blended orange (drawn as
    /// masks); double-sided ones brighter. Cut-out points show what lies behind them.
    Alpha,
}

impl DebugView {
    pub const ALL: [DebugView; 12] = [
        DebugView::None,
        DebugView::ClusterHeat,
        DebugView::GBufferAlbedo,
        DebugView::GBufferNormal,
        DebugView::GBufferMaterial,
        DebugView::Depth,
        DebugView::ShadowMap,
        DebugView::ShadowCube,
        DebugView::ShadowAtlas,
        DebugView::Meshlets,
        DebugView::Triangles,
        DebugView::Alpha,
    ];

    pub fn name(self) -> &'static str {
        match self {
            DebugView::None => "none",
            DebugView::ClusterHeat => "cluster-heat",
            DebugView::GBufferAlbedo => "gbuffer-albedo",
            DebugView::GBufferNormal => "gbuffer-normal",
            DebugView::GBufferMaterial => "gbuffer-material",
            DebugView::Depth => "depth",
            DebugView::ShadowMap => "shadow-map",
            DebugView::ShadowCube => "shadow-cube",
            DebugView::ShadowAtlas => "shadow-atlas",
            DebugView::Meshlets => "meshlets",
            DebugView::Triangles => "triangles",
            DebugView::Alpha => "alpha",
        }
    }

    pub fn from_name(name: &str) -> Result<DebugView, RenderError> {
        by_name(&DebugView::ALL, DebugView::name, Named::DebugView, name)
    }

    /// The value shaders see: `DEBUG_VIEW_*` in common/common.glsl, generated from there.
    pub fn code(self) -> u32 {
        use ml_shaders::debug_view as v;
        match self {
            DebugView::None => v::NONE,
            DebugView::ClusterHeat => v::CLUSTER_HEAT,
            DebugView::GBufferAlbedo => v::GBUFFER_ALBEDO,
            DebugView::GBufferNormal => v::GBUFFER_NORMAL,
            DebugView::GBufferMaterial => v::GBUFFER_MATERIAL,
            DebugView::Depth => v::DEPTH,
            DebugView::ShadowMap => v::SHADOW_MAP,
            DebugView::ShadowCube => v::SHADOW_CUBE,
            DebugView::ShadowAtlas => v::SHADOW_ATLAS,
            DebugView::Meshlets => v::MESHLETS,
            DebugView::Triangles => v::TRIANGLES,
            DebugView::Alpha => v::ALPHA,
        }
    }
}

/// Size of the biggest image we agree to render, whatever the device allows: 16384² RGBA8 is
/// 1 GiB of colour alone, per frame in flight.
pub const MAX_DIMENSION: u32 = 16384;

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
}

/// How bright the image is made (docs/DESIGN.md#exposure).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    /// Lit colour × 2^EV (0 changes nothing).
    Ev(f32),
    /// The EV that brings the image's log-average luminance to middle grey, metered on the
    /// GPU each frame (the exposure-meter pass) and applied to the next; a render's last frame
    /// is rendered again until the EV it used is the one its own image asks for.
    Auto,
}

/// The most |EV| `--exposure` takes (and auto exposure reaches): 2^±20 is a million times
/// brighter or darker, past any useful picture; beyond is a typo.
pub const MAX_EXPOSURE_EV: f32 = 20.0;

/// Parse `--exposure EV|auto`: auto, or a finite number of stops within ±MAX_EXPOSURE_EV.
pub fn parse_exposure(text: &str) -> Result<Exposure, RenderError> {
    if text.trim() == "auto" {
        return Ok(Exposure::Auto);
    }
    match text.trim().parse::<f32>() {
        Ok(ev) if ev.is_finite() && ev.abs() <= MAX_EXPOSURE_EV => Ok(Exposure::Ev(ev)),
        _ => Err(RenderError::Invalid(format!(
            "exposure '{text}' is neither auto nor a number of stops (EV) from -{MAX_EXPOSURE_EV} to {MAX_EXPOSURE_EV}"
        ))),
    }
}

/// The seed's timer runs at a quarter of real time (`timerSpeed *= 0.25`).
pub const TIMER_SPEED: f32 = 0.25;
pub const FRAME_SECONDS: f32 = 1.0 / 60.0;

impl RenderSettings {
    /// Defaults for everything but technique and size: the seed model, 16×9×24 clusters, one
    /// frame at time 0.
    pub fn new(technique: Technique, width: u32, height: u32) -> RenderSettings {
        RenderSettings {
            technique,
            shading: ShadingModel::Seed,
            clusters: ClusterDims::DEFAULT,
            debug_view: DebugView::None,
            omni: None,
            sun_shadow: SunShadowMode::Graphics,
            width,
            height,
            frames: 1,
            time: Some(0.0),
            culling: true,
            raster: Raster::Hardware,
            exposure: Exposure::Ev(0.0),
        }
    }

    /// The image's width over its height.
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// Whether the exposure-meter pass runs: auto exposure, on the shaded image (a debug view
    /// shows its values as they are).
    pub fn meters_exposure(&self) -> bool {
        self.exposure == Exposure::Auto && self.debug_view == DebugView::None
    }

    /// Animation clock of frame `i`.
    pub fn clock(&self, i: u32) -> f32 {
        self.time.unwrap_or(i as f32 * FRAME_SECONDS * TIMER_SPEED)
    }

    /// What the lighting pipelines are compiled for, for `scene`.
    pub fn lighting(&self, scene: &ml_cpu::scene::Scene) -> Shading {
        Shading {
            model: self.shading,
            omni_shadows: self.omni.is_some(),
            shadow_atlas: self.omni.is_some_and(|o| o.atlas().is_some()),
            object_textures: !scene.textures.is_empty(),
            spot_lights: !scene.cones.is_empty(),
        }
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
        if self.debug_view == DebugView::ClusterHeat && !self.technique.draws_cluster_heat() {
            return Err(SettingsError::HeatNeedsClusteredForward { technique: self.technique.name() }.into());
        }
        if matches!(self.debug_view, DebugView::Meshlets | DebugView::Triangles) && self.technique.geometry() != Geometry::Meshlets {
            return Err(SettingsError::ViewNeedsMeshlets { view: self.debug_view.name(), technique: self.technique.name() }.into());
        }
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
            // Its depth-and-id buffer, 8 bytes a pixel, is one storage buffer.
            let bytes = self.width as u64 * self.height as u64 * 8;
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
        if self.debug_view == DebugView::ShadowMap && self.shading != ShadingModel::BlinnPhong {
            return Err(SettingsError::ShadowMapNeedsBlinnPhong.into());
        }
        if self.debug_view == DebugView::ShadowCube && self.omni.is_none_or(|o| o.atlas().is_some()) {
            return Err(SettingsError::ShadowCubeNeedsShadows.into());
        }
        if self.debug_view == DebugView::ShadowAtlas && self.omni.is_none_or(|o| o.atlas().is_none()) {
            return Err(SettingsError::ShadowAtlasViewNeedsAtlas.into());
        }
        if let Some(omni) = &self.omni {
            check_omni(ctx, omni, lights)?;
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

/// Reject shadow-cube requests the device or the scene cannot take, before allocating.
fn check_omni(ctx: &Context, omni: &OmniShadowSettings, lights: usize) -> Result<(), SettingsError> {
    let limits = &ctx.info.limits;
    let device = || ctx.info.name.clone();
    if lights == 0 {
        return Err(SettingsError::ShadowsWithoutLights);
    }
    if omni.lights == 0 || (omni.lights as usize > lights && !omni.all) {
        return Err(SettingsError::ShadowedLights { value: omni.lights, lights });
    }
    if let Some(atlas) = omni.atlas() {
        return check_atlas(ctx, omni, atlas);
    }
    let max_cubes = limits.max_image_array_layers / 6;
    if omni.lights > max_cubes {
        return Err(SettingsError::TooManyCubes { value: omni.lights, max: max_cubes, device: device() });
    }
    let max_size = limits.max_image_dimension_cube.min(MAX_DIMENSION);
    if omni.size == 0 || omni.size > max_size {
        return Err(SettingsError::OutOfRange { what: Setting::CubeSize, value: omni.size, max: max_size });
    }
    if omni.bytes() > MAX_OMNI_BYTES {
        return Err(SettingsError::ShadowMemory {
            lights: omni.lights,
            size: omni.size,
            mib: omni.bytes() >> 20,
            max_mib: MAX_OMNI_BYTES >> 20,
        });
    }
    let missing = |feature, instead| SettingsError::MissingFeature { mode: omni.mode.name(), feature, device: device(), instead };
    if omni.mode == OmniShadowMode::Multiview && !ctx.info.features.multiview {
        return Err(missing("multiview", "layered, direct or copy"));
    }
    if omni.mode == OmniShadowMode::Multiview && multiview_depth_is_broken(ctx) {
        return Err(SettingsError::BrokenMultiview { device: device(), driver: ctx.info.driver_info.clone() });
    }
    if omni.mode == OmniShadowMode::Layered && !ctx.info.features.shader_output_layer {
        return Err(missing("shaderOutputLayer", "direct or copy"));
    }
    if let OmniShadowMode::Compute { .. } = omni.mode {
        check_compute_raster(ctx, omni)?;
        // The depths are one storage buffer, as large as the cubes.
        if omni.bytes() > limits.max_storage_buffer_range as u64 {
            return Err(SettingsError::ShadowBuffer {
                lights: omni.lights,
                size: omni.size,
                mib: omni.bytes() >> 20,
                device: device(),
                max_mib: limits.max_storage_buffer_range as u64 >> 20,
            });
        }
    }
    Ok(())
}

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

/// The settings a command asks for, before the scene is known: its cluster grid may be left
/// to the scene's light count, and its shading model comes with the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SettingsRequest {
    pub technique: Technique,
    /// Cluster grid; None: `ClusterDims::for_lights` for the scene's lights at this size.
    pub clusters: Option<ClusterDims>,
    pub debug_view: DebugView,
    pub omni: Option<OmniShadowSettings>,
    pub sun_shadow: SunShadowMode,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub time: Option<f32>,
    pub culling: bool,
    pub raster: Raster,
    pub exposure: Exposure,
}

impl SettingsRequest {
    /// The settings that render `scene` with `shading` (the model its request resolved to).
    pub fn for_scene(&self, scene: &ml_cpu::scene::Scene, shading: ShadingModel) -> RenderSettings {
        RenderSettings {
            technique: self.technique,
            shading,
            clusters: self.clusters.unwrap_or_else(|| ClusterDims::for_lights(scene.lights.len(), self.width, self.height)),
            debug_view: self.debug_view,
            omni: self.omni.map(|o| OmniShadowSettings { lights: shadowed_count(&o, scene, (self.width, self.height)), ..o }),
            sun_shadow: self.sun_shadow,
            width: self.width,
            height: self.height,
            frames: self.frames,
            time: self.time,
            culling: self.culling,
            raster: self.raster,
            exposure: self.exposure,
        }
    }
}

/// How many lights cast shadows: `--shadowed-lights all` counts those that reach the view
/// (at least one slot, so that a view without any still renders).
fn shadowed_count(omni: &OmniShadowSettings, scene: &ml_cpu::scene::Scene, (width, height): (u32, u32)) -> u32 {
    if !omni.all {
        return omni.lights;
    }
    let aspect = width.max(1) as f32 / height.max(1) as f32;
    let seen = ml_cpu::omni_shadow::lights_in_view(&scene.lights, &scene.camera, aspect, scene.light_motion, MAX_SHADOWED_LIGHTS as usize);
    (seen.len() as u32).max(1)
}

/// The first device feature the meshlet techniques need that `features` lacks, if any.
pub fn missing_meshlet_feature(features: &ml_vk::OptionalFeatures) -> Option<&'static str> {
    [
        (features.full_draw_index_uint32, "fullDrawIndexUint32 (32-bit index values)"),
        (features.geometry_shader, "geometryShader (gl_PrimitiveID in fragment shaders)"),
    ]
    .into_iter()
    .find_map(|(has, feature)| (!has).then_some(feature))
}
