//! The transparent resolve: a compute pass over the opaque pass's linear HDR image (the
//! forward pass's, the lighting subpass's, the compute lighting's) that lights each pixel's
//! transparent layers, blends them back to front over it and encodes the result into the
//! colour target (transparent_resolve.comp; in place of the deferred techniques' tone map).
//! Every technique's layers are lit and blended here, by one shader.

use super::layer_reads;
use crate::compute_pass::ComputePass;
use crate::frame_resources::FrameResources;
use crate::pass::{Pass, Recording};
use crate::scene::SceneGpu;
use crate::shading::Shading;
use crate::sync::{shading_reads, Use, HDR_TARGET};
use ml_vk::{vk, Context, VkError};

pub struct TransparentResolve {
    pass: ComputePass,
    /// A compute lighting pass wrote the HDR image (declared, in GENERAL) — else a render
    /// pass, whose dependencies order it and leave it SHADER_READ_ONLY_OPTIMAL.
    after_compute: bool,
}

impl TransparentResolve {
    /// `clustered`: the layers are lit by their clusters' lights (else by every light);
    /// `after_compute`: the HDR image is the compute lighting's.
    pub fn new(
        ctx: &Context,
        scene: &SceneGpu,
        shading: Shading,
        (clustered, after_compute): (bool, bool),
    ) -> Result<TransparentResolve, VkError> {
        let shader = if clustered { &ml_shaders::TRANSPARENT_RESOLVE_CLUSTERED_COMP } else { &ml_shaders::TRANSPARENT_RESOLVE_COMP };
        let constants = shading.layered_lighting_constants();
        Ok(TransparentResolve { pass: ComputePass::new(ctx, &[scene.textures.set_layout.raw], (shader, &constants))?, after_compute })
    }
}

impl Pass for TransparentResolve {
    fn timer_name(&self) -> Option<&'static str> {
        Some("transparent resolve")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let hdr = self.pass.sampled(&frame.targets.hdr, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        self.pass.bind_frame(ctx, frame, &|name| if name == "hdr_image" { hdr } else { frame.buffer(name) })
    }

    /// After the layers' build and the opaque pass that wrote the HDR image.
    fn uses(&self) -> Vec<Use> {
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let mut uses = shading_reads(compute);
        uses.extend(layer_reads(compute));
        if self.after_compute {
            let layout = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
            uses.push(Use::at(HDR_TARGET, (compute, vk::AccessFlags::SHADER_READ), Some(layout)));
        }
        uses.push(ComputePass::colour_use());
        uses
    }

    fn record(&self, rec: &Recording) {
        let sets = [rec.scene.textures.set];
        self.pass.record_into_colour_target(rec.ctx, rec.cmd, (rec.slot, &sets), rec.targets.color.raw, rec.extent);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
    }
}
