//! A compute pass over the image that writes the colour target (the compute lighting, the tone
//! map, the shadow-map view): one pipeline, its set 0 per frame slot (laid out as the shader
//! declares it), a fetch sampler for its inputs.

use crate::descriptors::{FrameSets, Resource};
use crate::frame::FRAMES_IN_FLIGHT;
use ml_shaders::Shader;
use ml_vk::image::{fetch_sampler, image_transition};
use ml_vk::{shader, vk, Context, VkError};

/// Work-group size of these passes (8×8 in the shaders).
const GROUP: u32 = 8;

pub struct ComputePass {
    sets: FrameSets,
    pub sampler: vk::Sampler,
    pipeline_layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
}

impl ComputePass {
    /// The pass of `shader` (with specialization `constants`: id, value); set 0 as the shader
    /// declares it, further sets of `more_sets`.
    pub fn new(
        ctx: &Context,
        more_sets: &[vk::DescriptorSetLayout],
        (shader, constants): (&Shader, &[(u32, u32)]),
    ) -> Result<ComputePass, VkError> {
        let p = ComputePass {
            sets: FrameSets::new(ctx, &[(shader, vk::ShaderStageFlags::COMPUTE)], 0, FRAMES_IN_FLIGHT)?,
            sampler: vk::Sampler::null(),
            pipeline_layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
        };
        ml_vk::build(ctx, p, |p| {
            let layouts: Vec<vk::DescriptorSetLayout> = std::iter::once(p.sets.layout.raw).chain(more_sets.iter().copied()).collect();
            p.pipeline_layout = shader::pipeline_layout(ctx, &layouts, &[])?;
            p.pipeline = shader::compute_pipeline(ctx, shader.spirv, p.pipeline_layout, constants)?;
            p.sampler = fetch_sampler(ctx)?;
            Ok(())
        })
    }

    /// Point slot `slot`'s set 0 at what `lookup` names.
    pub fn bind_frame(&self, ctx: &Context, slot: usize, lookup: &dyn Fn(&str) -> Option<Resource>) -> Result<(), VkError> {
        self.sets.write(ctx, slot, lookup)
    }

    /// Run over `extent` with slot `slot`'s set 0 and `more_sets` after it, writing `color` as a
    /// storage image, and leave it as the forward pass leaves its own target: in
    /// TRANSFER_SRC_OPTIMAL, ready for the read-back.
    pub fn record_into_colour_target(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        (slot, more_sets): (usize, &[vk::DescriptorSet]),
        color: vk::Image,
        extent: vk::Extent2D,
    ) {
        let sets: Vec<vk::DescriptorSet> = std::iter::once(self.sets.sets[slot]).chain(more_sets.iter().copied()).collect();
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let d = &ctx.device;
        // The colour image was last read by a copy two frames ago (same queue).
        let storage = (compute, vk::AccessFlags::SHADER_WRITE, vk::ImageLayout::GENERAL);
        image_transition(ctx, cmd, color, (transfer, vk::AccessFlags::empty(), vk::ImageLayout::UNDEFINED), storage);
        // SAFETY: recording state outside a render pass; everything bound is alive.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline_layout, 0, &sets, &[]);
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
        }
        self.sets.destroy(ctx);
        self.sampler = vk::Sampler::null();
        self.pipeline_layout = vk::PipelineLayout::null();
        self.pipeline = vk::Pipeline::null();
    }
}

impl ml_vk::Release for ComputePass {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
