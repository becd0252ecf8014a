//! What pixels no surface covers show (`--background`): a fixed dark colour, or the scene's
//! environment along each pixel's ray — exposed and tone-mapped as the surfaces' light is,
//! from the environment's radiance cube at the mip level whose texels are about a pixel wide
//! (common/background.glsl). Whoever writes a pixel's final colour lays the backdrop: the
//! compute lightings, the tone map, the transparent layers' resolve and, after the forward pass
//! without anti-aliasing or layers (which writes the output directly), `Backdrop`.

use crate::compute_pass::ComputePass;
use crate::error::{by_name, Named, RenderError};
use crate::frame_resources::FrameResources;
use crate::pass::{Pass, Recording};
use crate::sync::{Use, COLOUR_TARGET};
use ml_cpu::environment::Environment;
use ml_cpu::scene::Scene;
use ml_cpu::shading_model::ShadingModel;
use ml_vk::{vk, Context, VkError};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Background {
    /// The fixed colour (mesh_raster.rs CLEAR_COLOR).
    #[default]
    Colour,
    /// The scene's environment (pbr with an environment; debug views keep the colour).
    Environment,
}

impl Background {
    pub const ALL: [Background; 2] = [Background::Colour, Background::Environment];

    pub fn name(self) -> &'static str {
        match self {
            Background::Colour => "colour",
            Background::Environment => "environment",
        }
    }

    pub fn from_name(name: &str) -> Result<Background, RenderError> {
        by_name(&Background::ALL, Background::name, Named::Background, name)
    }

    /// What `scene` asks to show with `model`: its environment where it asks to be shown and
    /// lights the model (pbr), else the colour.
    pub fn asked_by(scene: &Scene, model: ShadingModel) -> Background {
        let shown = scene.sections.get::<Environment>().is_some_and(|e| e.background) && model == ShadingModel::Pbr;
        if shown {
            Background::Environment
        } else {
            Background::Colour
        }
    }

    /// `BACKGROUND_ENVIRONMENT` (common/background.glsl) of the pipelines that lay it.
    pub fn constant(self) -> (&'static str, u32) {
        ("BACKGROUND_ENVIRONMENT", u32::from(self == Background::Environment))
    }
}

/// The forward pass's pixels without a surface (alpha 0: the pass cleared them so and draws
/// alpha 1) given the environment (shading/backdrop.comp).
pub struct Backdrop {
    pass: ComputePass,
}

impl Backdrop {
    /// `textures`: set 1's layout (the scene's textures, of which the environment).
    pub fn new(ctx: &Context, textures: vk::DescriptorSetLayout) -> Result<Backdrop, VkError> {
        let constants = [Background::Environment.constant()];
        Ok(Backdrop { pass: ComputePass::new(ctx, &[textures], (&ml_shaders::BACKDROP_COMP, &constants))? })
    }
}

impl Pass for Backdrop {
    fn timer_name(&self) -> Option<&'static str> {
        Some("background")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.pass.bind_frame(ctx, frame)
    }

    /// Reads what the forward pass wrote and writes the rest.
    fn uses(&self) -> Vec<Use> {
        let access = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        vec![Use::image(COLOUR_TARGET, (vk::PipelineStageFlags::COMPUTE_SHADER, access), vk::ImageLayout::GENERAL)]
    }

    fn record(&self, rec: &Recording) {
        self.pass.record_into_colour_target(rec.ctx, rec.cmd, (rec.slot, &[rec.scene.textures.set]), rec.targets.color.raw, rec.extent);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
    }
}
