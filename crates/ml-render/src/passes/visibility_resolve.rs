//! The compute raster's resolve (visibility_resolve.comp): its 64-bit buffer of depth and id
//! per pixel made into the depth and visibility images that the hardware raster would have
//! left, so the depth pyramid and the lighting read the same images whichever rasteriser drew
//! them. Once per culling phase: the pyramid reads the early result, the lighting the late.

use crate::compute_pass::ComputePass;
use crate::descriptors::Resource;
use crate::pass::{FrameResources, Pass, Recording};
use crate::passes::meshlet_cull::Phase;
use ml_vk::commands::memory_barrier;
use ml_vk::image::image_transition;
use ml_vk::{vk, Context, VkError};

pub struct VisibilityResolve {
    phase: Phase,
    pass: ComputePass,
}

impl VisibilityResolve {
    pub fn new(ctx: &Context, phase: Phase) -> Result<VisibilityResolve, VkError> {
        Ok(VisibilityResolve { phase, pass: ComputePass::with_push(ctx, &[], (&ml_shaders::VISIBILITY_RESOLVE_COMP, &[]), 16)? })
    }
}

impl Pass for VisibilityResolve {
    fn timer_name(&self) -> Option<&'static str> {
        Some(match self.phase {
            Phase::Early => "resolve (early)",
            Phase::Late => "resolve (late)",
        })
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let t = frame.targets;
        let storage =
            |view| Some(Resource::Image(vk::DescriptorImageInfo::default().image_view(view).image_layout(vk::ImageLayout::GENERAL)));
        self.pass.bind_frame(ctx, frame, &|name| match name {
            "visibility_out" => storage(t.visibility.view),
            "depth_out" => storage(t.depth.view),
            _ => frame.buffer(name),
        })
    }

    /// After the phase's compute and hardware rasters (their passes make the buffer visible
    /// to compute); the depth pyramid or the lighting reads the images.
    fn record(&self, rec: &Recording) {
        let (ctx, cmd, t) = (rec.ctx, rec.cmd, rec.targets);
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        // Every pixel is written: what the images held (read by the last frame's lighting on
        // this slot, or by this frame's pyramid; written by the early resolve) is discarded.
        for image in [&t.visibility, &t.depth] {
            let (undefined, general) = (vk::ImageLayout::UNDEFINED, vk::ImageLayout::GENERAL);
            let write = vk::AccessFlags::SHADER_WRITE;
            image_transition(ctx, cmd, image.raw, (compute, write, undefined), (compute, write, general));
        }
        let push = [rec.extent.width, rec.extent.height, 0, 0];
        self.pass.dispatch(ctx, cmd, rec.slot, (&[], bytemuck::cast_slice(&push)), rec.extent);
        memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (compute, vk::AccessFlags::SHADER_READ));
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
    }
}
