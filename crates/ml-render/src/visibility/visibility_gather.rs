//! Anti-aliasing with the hardware visibility raster (docs/DESIGN.md#anti-aliasing): after each
//! phase's multisampled draw, a compute pass gathers the ids and depths of every sample into
//! the 64-bit buffer the compute raster writes (visibility_gather.comp), so that the depth
//! pyramid, the light grid's marks and the lighting read one layout whichever raster drew.

use crate::antialiasing::Antialiasing;
use crate::compute_pass::ComputePass;
use crate::frame_resources::FrameResources;
use crate::pass::{Pass, Recording};
use crate::plan::Phase;
use crate::sync::{Use, VISIBILITY_DEPTH};
use ml_vk::{vk, Context, VkError};

pub struct VisibilityGather {
    pass: ComputePass,
    phase: Phase,
}

impl VisibilityGather {
    /// The gather after `phase`'s draw of `antialiasing`'s samples.
    pub fn new(ctx: &Context, phase: Phase, antialiasing: Antialiasing) -> Result<VisibilityGather, VkError> {
        let pass = ComputePass::new(ctx, &[], (&ml_shaders::VISIBILITY_GATHER_COMP, &[antialiasing.constant()]))?;
        Ok(VisibilityGather { pass, phase })
    }
}

impl Pass for VisibilityGather {
    fn timer_name(&self) -> Option<&'static str> {
        Some(match self.phase {
            Phase::Early => "samples gathered (early)",
            Phase::Late => "samples gathered (late)",
        })
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.pass.bind_frame(ctx, frame)
    }

    /// The images, after the raster's render pass (whose outgoing dependency makes them
    /// visible to compute); every sample of the buffer written.
    fn uses(&self) -> Vec<Use> {
        vec![Use::buffer(VISIBILITY_DEPTH, (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_WRITE))]
    }

    fn record(&self, rec: &Recording) {
        self.pass.dispatch(rec.ctx, rec.cmd, rec.slot, (&[], &[]), rec.extent);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
    }
}
