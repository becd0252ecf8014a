//! After the deferred render pass: the HDR image (linear RGBA16F) → the 8-bit colour target
//! that is read back, with the encoding the forward path applies in its fragment shader
//! (tonemap.comp). A compute pass: on H100/H200 it runs on every SM.

use crate::background::Background;
use crate::compute_pass::ComputePass;
use crate::frame_resources::FrameResources;
use crate::pass::{Pass, Recording};
use crate::scene::SceneGpu;
use crate::sync::Use;
use ml_vk::{Context, VkError};

pub struct ToneMap {
    pass: ComputePass,
}

impl ToneMap {
    /// `aces`: apply pbr's tone-mapping curve before gamma (not for debug views, whose
    /// values are shown as they are); `display_linear`: the image holds the display's linear
    /// light already (anti-aliasing's resolved samples), which only needs the gamma curve.
    /// Pixels without a surface get `background` (set 1: the scene's textures, of which
    /// the environment).
    pub fn new(ctx: &Context, scene: &SceneGpu, (aces, display_linear): (bool, bool), background: Background) -> Result<ToneMap, VkError> {
        let constants = [("MODEL_PBR", u32::from(aces)), ("DISPLAY_LINEAR_INPUT", u32::from(display_linear)), background.constant()];
        let textures = scene.textures.set_layout.raw;
        Ok(ToneMap { pass: ComputePass::new(ctx, &[textures], (&ml_shaders::TONEMAP_COMP, &constants))? })
    }
}

impl Pass for ToneMap {
    fn timer_name(&self) -> Option<&'static str> {
        Some("tone map")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.pass.bind_frame(ctx, frame)
    }

    /// After the render pass, whose outgoing dependency orders the HDR writes before this
    /// pass's reads.
    fn uses(&self) -> Vec<Use> {
        vec![ComputePass::colour_use()]
    }

    fn record(&self, rec: &Recording) {
        self.pass.record_into_colour_target(rec.ctx, rec.cmd, (rec.slot, &[rec.scene.textures.set]), rec.targets.color.raw, rec.extent);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
    }
}
