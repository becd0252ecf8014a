//! A compute pass over the image that writes the colour target (deferred-compute's lighting,
//! the deferred tone map): one set layout, one pipeline, a fetch sampler for its inputs.

use ml_vk::commands::image_transition;
use ml_vk::image::fetch_sampler;
use ml_vk::{shader, vk, Context, VkError};

/// Work-group size of these passes (8×8 in the shaders).
const GROUP: u32 = 8;

pub struct ComputePass {
    pub set_layout: vk::DescriptorSetLayout,
    pub sampler: vk::Sampler,
    pipeline_layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
}

impl ComputePass {
    /// The pass of `spirv` (with specialization `constants`: id, value) with set 0 of
    /// `bindings` and further sets of `more_sets`.
    pub fn new(
        ctx: &Context,
        bindings: &[(u32, vk::DescriptorType)],
        more_sets: &[vk::DescriptorSetLayout],
        (spirv, constants): (&[u8], &[(u32, u32)]),
    ) -> Result<ComputePass, VkError> {
        let p = ComputePass {
            set_layout: vk::DescriptorSetLayout::null(),
            sampler: vk::Sampler::null(),
            pipeline_layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
        };
        ml_vk::build(ctx, p, |p| {
            p.set_layout = shader::set_layout(ctx, bindings, vk::ShaderStageFlags::COMPUTE)?;
            let layouts: Vec<vk::DescriptorSetLayout> = std::iter::once(p.set_layout).chain(more_sets.iter().copied()).collect();
            p.pipeline_layout = shader::pipeline_layout(ctx, &layouts, &[])?;
            p.pipeline = shader::compute_pipeline(ctx, spirv, p.pipeline_layout, constants)?;
            p.sampler = fetch_sampler(ctx)?;
            Ok(())
        })
    }

    /// Run over `extent` with `sets` (from set 0), writing `color` as a storage image, and leave it as the
    /// forward pass leaves its own target: in TRANSFER_SRC_OPTIMAL, ready for the read-back.
    pub fn record_into_colour_target(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        sets: &[vk::DescriptorSet],
        color: vk::Image,
        extent: vk::Extent2D,
    ) {
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let d = &ctx.device;
        // The colour image was last read by a copy two frames ago (same queue).
        let storage = (compute, vk::AccessFlags::SHADER_WRITE, vk::ImageLayout::GENERAL);
        image_transition(ctx, cmd, color, (transfer, vk::AccessFlags::empty(), vk::ImageLayout::UNDEFINED), storage);
        // SAFETY: recording state outside a render pass; everything bound is alive.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline_layout, 0, sets, &[]);
            d.cmd_dispatch(cmd, extent.width.div_ceil(GROUP), extent.height.div_ceil(GROUP), 1);
        }
        image_transition(ctx, cmd, color, storage, (transfer, vk::AccessFlags::TRANSFER_READ, vk::ImageLayout::TRANSFER_SRC_OPTIMAL));
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the device is idle; null handles are ignored.
        unsafe {
            ctx.device.destroy_sampler(self.sampler, None);
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline_layout(self.pipeline_layout, None);
            ctx.device.destroy_descriptor_set_layout(self.set_layout, None);
        }
        *self = ComputePass {
            set_layout: vk::DescriptorSetLayout::null(),
            sampler: vk::Sampler::null(),
            pipeline_layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
        };
    }
}

impl ml_vk::Release for ComputePass {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
