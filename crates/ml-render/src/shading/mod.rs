//! The mesh techniques' raster passes: forward (brute force or clustered), the deferred
//! subpasses, the G-buffer and its compute lighting, and the render pass and mesh pipelines
//! they share.

pub mod compute_lighting;
pub mod deferred_subpass;
pub mod forward;
pub mod gbuffer;
pub mod mesh_raster;

use crate::antialiasing::Antialiasing;
use crate::background::Background;
use crate::targets::GBufferKind;
use ml_cpu::shading_model::ShadingModel;

/// What a lighting pipeline is compiled for: the model, whether point lights cast shadows,
/// whether objects have textures of their own and whether there are spot lights
/// (specialization constants, so each pipeline carries only what it runs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shading {
    pub model: ShadingModel,
    pub omni_shadows: bool,
    /// The point lights' shadows are in the shadow atlas (else in the cube array).
    pub shadow_atlas: bool,
    /// The point lights' shadows are shadow rays (no cubes).
    pub shadow_rays: bool,
    /// The point lights' shadows are maps and the scene has directional lights, which cast
    /// theirs by rays (`DIRECTIONAL_RAYS`).
    pub directional_rays: bool,
    /// The sun's shadow is a shadow ray (no map; blinn-phong).
    pub sun_rays: bool,
    pub object_textures: bool,
    pub spot_lights: bool,
    /// Transparent objects are blended in per-pixel layers (the opaque passes skip them).
    pub transparency: bool,
    /// The compute lightings count the shadow rays they trace (`--light-stats` with rays).
    pub count_rays: bool,
    /// Coverage samples per pixel: the mesh techniques draw into multisampled attachments and
    /// light in the display's linear light (`display_constant`).
    pub antialiasing: Antialiasing,
    /// Highlights under normal maps widened by the normals' spread (`SPECULAR_AA`).
    pub specular_aa: bool,
    /// The pbr model lit by the scene's environment instead of its constant ambient
    /// (`ENVIRONMENT`, environment/environment.glsl).
    pub environment: bool,
    /// Some object's material has glTF's PBR extensions (`MATERIAL_LOBES`,
    /// common/material_lobes.glsl; pbr).
    pub material_lobes: bool,
    /// Some object's extensions vary over its surface (`LOBE_TEXTURES`, Scene::has_lobe_textures;
    /// with `material_lobes`): read per point, kept per point by the G-buffer and the layers.
    pub lobe_textures: bool,
    /// What pixels no surface covers show (`BACKGROUND_ENVIRONMENT` where the pass lays it).
    pub background: Background,
}

impl Shading {
    /// The specialization constants (name, value) of a pipeline that reads surfaces without
    /// lighting them (the G-buffer's): `MODEL_BLINN_PHONG`, `MODEL_PBR`, `OBJECT_TEXTURES`,
    /// `SPECULAR_AA` and `LOBE_TEXTURES` (common/shading_model.glsl).
    pub fn surface_constants(self) -> [(&'static str, u32); 5] {
        [
            ("MODEL_BLINN_PHONG", u32::from(self.model == ShadingModel::BlinnPhong)),
            ("MODEL_PBR", u32::from(self.model == ShadingModel::Pbr)),
            ("OBJECT_TEXTURES", u32::from(self.object_textures)),
            ("SPECULAR_AA", u32::from(self.specular_aa)),
            ("LOBE_TEXTURES", u32::from(self.lobe_textures)),
        ]
    }

    /// Which images the scene's G-buffer has.
    pub fn gbuffer_kind(self) -> GBufferKind {
        if self.lobe_textures {
            GBufferKind::Lobes
        } else if self.object_textures {
            GBufferKind::Material
        } else {
            GBufferKind::Base
        }
    }

    /// The specialization constants (name, value) of a lighting pipeline: the surface's,
    /// `OMNI_SHADOWS`, `SHADOW_ATLAS`, `SHADOW_RAYS` and `DIRECTIONAL_RAYS` (shadows/omni_shadow.glsl),
    /// `SUN_RAYS` (common/blinn_phong.glsl), `SPOT_LIGHTS` (common/lighting.glsl) and
    /// `ENVIRONMENT` (environment/environment.glsl) and `MATERIAL_LOBES`.
    pub fn lighting_constants(self) -> [(&'static str, u32); 13] {
        let [model_a, model_b, textures, specular, lobe_textures] = self.surface_constants();
        [
            model_a,
            model_b,
            textures,
            specular,
            lobe_textures,
            ("OMNI_SHADOWS", u32::from(self.omni_shadows)),
            ("SHADOW_ATLAS", u32::from(self.shadow_atlas)),
            ("SHADOW_RAYS", u32::from(self.shadow_rays)),
            ("DIRECTIONAL_RAYS", u32::from(self.directional_rays)),
            ("SUN_RAYS", u32::from(self.sun_rays)),
            ("SPOT_LIGHTS", u32::from(self.spot_lights)),
            ("ENVIRONMENT", u32::from(self.environment)),
            ("MATERIAL_LOBES", u32::from(self.material_lobes)),
        ]
    }

    /// `lighting_constants`, `COUNT_RAYS` (shading/compute_shading.glsl) and the background's:
    /// the compute lightings' (they lay the background where no surface is).
    pub fn compute_lighting_constants(self) -> [(&'static str, u32); 15] {
        let [a, b, c, d, e, f, g, h, i, j, k, l, m] = self.lighting_constants();
        [a, b, c, d, e, f, g, h, i, j, k, l, m, ("COUNT_RAYS", u32::from(self.count_rays)), self.background.constant()]
    }

    /// `lighting_constants`, `TRANSPARENT_LAYERS` (shading/forward_frag.glsl: the forward
    /// pass of a scene with transparent layers writes linear HDR for their resolve), the
    /// samples per pixel its masks are tested at and `display_constant`: the forward pass's.
    pub fn forward_lighting_constants(self) -> [(&'static str, u32); 16] {
        let [a, b, c, d, e, f, g, h, i, j, k, l, m] = self.lighting_constants();
        let layers = ("TRANSPARENT_LAYERS", u32::from(self.transparency));
        [a, b, c, d, e, f, g, h, i, j, k, l, m, layers, self.antialiasing.constant(), self.display_constant()]
    }

    /// `DISPLAY_LINEAR_OUTPUT` (shading/display_output.glsl): with anti-aliasing, the forward
    /// pass writes the display's linear light, in which its samples are averaged and which the
    /// tone map only gamma-encodes.
    pub fn display_constant(self) -> (&'static str, u32) {
        ("DISPLAY_LINEAR_OUTPUT", u32::from(self.antialiasing != Antialiasing::Off))
    }
}
