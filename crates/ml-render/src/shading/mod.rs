//! The mesh techniques' raster passes: forward (brute force or clustered), the deferred
//! subpasses, the G-buffer and its compute lighting, and the render pass and mesh pipelines
//! they share.

pub mod blinn_phong;
pub mod compute_lighting;
pub mod deferred_subpass;
pub mod forward;
pub mod gbuffer;
pub mod mesh_raster;

use crate::antialiasing::Antialiasing;
use crate::background::Background;
use crate::debug_view::{DebugView, Drawn, ViewSpec};
use crate::specialization::{Constant, Constants};
use crate::targets::GBufferKind;
use ml_cpu::scene::Scene;
use ml_cpu::shading_model::ShadingModel;

/// A surface view: the values a technique shades with, shown as they are over the opaque
/// surfaces, in any technique.
const fn surface_view(name: &'static str, code: u32) -> ViewSpec {
    ViewSpec::plain(name, code, &[], Drawn::InShading { toned: false, layers: false })
}

/// The G-buffer's channels (any technique: the values it shades with): albedo (texture
/// included), normal·0.5 + 0.5, (roughness, metallic, 0); view depth, ln(depth/near) /
/// ln(far/near) in grey; which surfaces alpha masks cut: opaque grey, masked green, blended
/// orange (drawn as masks), double-sided ones brighter, cut-out points showing what lies
/// behind them.
pub(crate) const VIEWS: &[DebugView] = {
    use ml_shaders::debug_view as code;
    &[
        DebugView { spec: &surface_view("gbuffer-albedo", code::GBUFFER_ALBEDO) },
        DebugView { spec: &surface_view("gbuffer-normal", code::GBUFFER_NORMAL) },
        DebugView { spec: &surface_view("gbuffer-material", code::GBUFFER_MATERIAL) },
        DebugView { spec: &surface_view("depth", code::DEPTH) },
        DebugView { spec: &surface_view("alpha", code::ALPHA) },
    ]
};

/// What a lighting pipeline is compiled for: each feature's specialization constants (so each
/// pipeline carries only what it runs), contributed from the feature's module by
/// `RenderSettings::lighting`, and what the passes themselves choose by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shading {
    /// The constants of pipelines that read surfaces (the G-buffer's too): `surface_constants`.
    pub surface: Constants,
    /// What lighting them adds: the shadows', the lights', the environment's, the material
    /// extensions'.
    pub lighting: Constants,
    /// Transparent objects are blended in per-pixel layers (the opaque passes skip them).
    pub transparency: bool,
    /// The visibility rasters draw transparent objects' points of alpha 1 as opaque and the
    /// layers hold the rest (blended_cores.glsl): layers on, the meshlet technique.
    pub blended_cores: bool,
    /// The compute lightings count the shadow rays they trace (`--light-stats` with rays).
    pub count_rays: bool,
    /// Coverage samples per pixel: the mesh techniques draw into multisampled attachments and
    /// light in the display's linear light (`display_constant`).
    pub antialiasing: Antialiasing,
    /// What pixels no surface covers show (`BACKGROUND_ENVIRONMENT` where the pass lays it).
    pub background: Background,
}

/// The surface's constants (common/shading_model.glsl): the model, whether objects have
/// textures of their own, whether highlights under normal maps widen by the normals' spread
/// (`SPECULAR_AA`), whether the PBR extensions vary over a surface (`LOBE_TEXTURES`,
/// Scene::has_lobe_textures: read per point, kept per point by the G-buffer and the layers).
pub fn surface_constants(model: ShadingModel, object_textures: bool, specular_aa: bool, lobe_textures: bool) -> [(&'static str, u32); 5] {
    [
        ("MODEL_BLINN_PHONG", u32::from(model == ShadingModel::BlinnPhong)),
        ("MODEL_PBR", u32::from(model == ShadingModel::Pbr)),
        ("OBJECT_TEXTURES", u32::from(object_textures)),
        ("SPECULAR_AA", u32::from(specular_aa)),
        ("LOBE_TEXTURES", u32::from(lobe_textures)),
    ]
}

/// Whether the scene's materials use glTF's PBR extensions (`MATERIAL_LOBES`,
/// common/material_lobes.glsl; pbr).
pub fn material_lobes(model: ShadingModel, scene: &Scene) -> bool {
    model == ShadingModel::Pbr && scene.objects.iter().any(|o| o.extras.lobes.any())
}

/// The lights' and the materials' lighting constants: `SPOT_LIGHTS` (common/lighting.glsl)
/// and `MATERIAL_LOBES`.
pub fn light_constants(model: ShadingModel, scene: &Scene) -> [(&'static str, u32); 2] {
    [("SPOT_LIGHTS", u32::from(!scene.cones.is_empty())), ("MATERIAL_LOBES", u32::from(material_lobes(model, scene)))]
}

impl Shading {
    /// The specialization constants (name, value) of a pipeline that reads surfaces without
    /// lighting them (the G-buffer's).
    pub fn surface_constants(&self) -> &[(&'static str, u32)] {
        self.surface.as_slice()
    }

    /// `BLENDED_CORES` for the passes that draw or leave out transparent objects' cores,
    /// where they are drawn (else nothing: the constant's default is off).
    pub fn cores_constant(&self) -> Option<Constant> {
        self.blended_cores.then_some(("BLENDED_CORES", 1))
    }

    /// The value of constant `name` for these settings, where a feature sets it.
    pub fn constant(&self, name: &str) -> Option<u32> {
        self.surface.get(name).or_else(|| self.lighting.get(name))
    }

    /// Whether constant `name` is set and on.
    fn on(&self, name: &str) -> bool {
        self.constant(name).is_some_and(|v| v != 0)
    }

    /// Which images the scene's G-buffer has.
    pub fn gbuffer_kind(&self) -> GBufferKind {
        if self.on("LOBE_TEXTURES") {
            GBufferKind::Lobes
        } else if self.on("OBJECT_TEXTURES") {
            GBufferKind::Material
        } else {
            GBufferKind::Base
        }
    }

    /// Whether surfaces' PBR extensions vary per point (their texels kept per point).
    pub fn lobe_textures(&self) -> bool {
        self.on("LOBE_TEXTURES")
    }

    /// The specialization constants (name, value) of a lighting pipeline: the surface's and
    /// every lighting feature's.
    pub fn lighting_constants(&self) -> Vec<(&'static str, u32)> {
        [self.surface.as_slice(), self.lighting.as_slice()].concat()
    }

    /// `lighting_constants`, `COUNT_RAYS` (shading/compute_shading.glsl) and the background's:
    /// the compute lightings' (they lay the background where no surface is).
    pub fn compute_lighting_constants(&self) -> Vec<(&'static str, u32)> {
        let mut c = self.lighting_constants();
        c.extend([("COUNT_RAYS", u32::from(self.count_rays)), self.background.constant()]);
        c
    }

    /// `lighting_constants`, `TRANSPARENT_LAYERS` (shading/forward_frag.glsl: the forward
    /// pass of a scene with transparent layers writes linear HDR for their resolve), the
    /// samples per pixel its masks are tested at and `display_constant`: the forward pass's.
    pub fn forward_lighting_constants(&self) -> Vec<(&'static str, u32)> {
        let mut c = self.lighting_constants();
        c.extend([("TRANSPARENT_LAYERS", u32::from(self.transparency)), self.antialiasing.constant(), self.display_constant()]);
        c
    }

    /// `DISPLAY_LINEAR_OUTPUT` (shading/display_output.glsl): with anti-aliasing, the forward
    /// pass writes the display's linear light, in which its samples are averaged and which the
    /// tone map only gamma-encodes.
    pub fn display_constant(&self) -> (&'static str, u32) {
        ("DISPLAY_LINEAR_OUTPUT", u32::from(self.antialiasing != Antialiasing::Off))
    }
}
