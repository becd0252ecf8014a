//! Technique `deferred-compute`: the raster pass writes a G-buffer (raster.rs, Output::GBuffer)
//! and this compute pass lights it through the clustered-gpu lists — the same BRDF, cluster
//! lookup and light order as the fragment path, on every SM (H100/H200 give graphics work 4 of
//! 132). Its output is the colour target, left in TRANSFER_SRC_OPTIMAL like the forward pass's.

use crate::targets::Targets;
use ml_cpu::gpu_types::ObjectPush;
use ml_vk::commands::image_transition;
use ml_vk::descriptors::{allocate_set, write_buffer};
use ml_vk::{shader, vk, Buffer, Context, VkError, VkResultExt};

/// Bindings of the lighting set (deferred_lighting.comp).
pub const BINDING_FRAME: u32 = 0;
pub const BINDING_LIGHTS: u32 = 1;
pub const BINDING_RANGES: u32 = 2;
pub const BINDING_INDICES: u32 = 3;
pub const BINDING_OBJECTS: u32 = 4;
pub const BINDING_DEPTH: u32 = 5;
pub const BINDING_NORMAL: u32 = 6;
pub const BINDING_OBJECT_ID: u32 = 7;
pub const BINDING_OUTPUT: u32 = 8;

const GROUP: u32 = 8;

pub struct ComputeLighting {
    pub set_layout: vk::DescriptorSetLayout,
    pipeline_layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    sampler: vk::Sampler,
    /// Every object's material and index (what the raster pass pushes), device-local.
    objects: Buffer,
}

/// Descriptors of one frame's lighting set.
pub struct LightingInputs<'a> {
    pub uniforms: vk::Buffer,
    pub lights: vk::Buffer,
    pub ranges: vk::Buffer,
    pub indices: vk::Buffer,
    pub targets: &'a Targets,
}

impl ComputeLighting {
    pub fn new(ctx: &Context, objects: &[ObjectPush]) -> Result<ComputeLighting, VkError> {
        let l = ComputeLighting {
            set_layout: vk::DescriptorSetLayout::null(),
            pipeline_layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            sampler: vk::Sampler::null(),
            objects: Buffer::null(),
        };
        ml_vk::build(ctx, l, |l| l.create(ctx, objects))
    }

    fn create(&mut self, ctx: &Context, objects: &[ObjectPush]) -> Result<(), VkError> {
        use vk::DescriptorType as T;
        let storage = T::STORAGE_BUFFER;
        let image = T::COMBINED_IMAGE_SAMPLER;
        self.set_layout = shader::set_layout(
            ctx,
            &[
                (BINDING_FRAME, T::UNIFORM_BUFFER),
                (BINDING_LIGHTS, storage),
                (BINDING_RANGES, storage),
                (BINDING_INDICES, storage),
                (BINDING_OBJECTS, storage),
                (BINDING_DEPTH, image),
                (BINDING_NORMAL, image),
                (BINDING_OBJECT_ID, image),
                (BINDING_OUTPUT, T::STORAGE_IMAGE),
            ],
            vk::ShaderStageFlags::COMPUTE,
        )?;
        self.pipeline_layout = shader::pipeline_layout(ctx, &[self.set_layout], &[])?;
        self.pipeline = shader::compute_pipeline(ctx, ml_shaders::DEFERRED_LIGHTING_COMP, self.pipeline_layout, &[])?;
        // texelFetch ignores filtering; the sampler only has to exist.
        let sampler_info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::NEAREST)
            .min_filter(vk::Filter::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE);
        // SAFETY: as above.
        self.sampler = unsafe { ctx.device.create_sampler(&sampler_info, None) }.ctx("vkCreateSampler")?;
        self.objects = Buffer::device_local_with(ctx, "objects", bytemuck::cast_slice(objects), vk::BufferUsageFlags::STORAGE_BUFFER)?;
        Ok(())
    }

    /// Allocate and fill a frame's lighting set.
    pub fn frame_set(&self, ctx: &Context, pool: vk::DescriptorPool, inputs: &LightingInputs) -> Result<vk::DescriptorSet, VkError> {
        let set = allocate_set(ctx, pool, self.set_layout)?;
        write_buffer(ctx, set, BINDING_FRAME, vk::DescriptorType::UNIFORM_BUFFER, inputs.uniforms);
        for (binding, buffer) in [
            (BINDING_LIGHTS, inputs.lights),
            (BINDING_RANGES, inputs.ranges),
            (BINDING_INDICES, inputs.indices),
            (BINDING_OBJECTS, self.objects.raw),
        ] {
            write_buffer(ctx, set, binding, vk::DescriptorType::STORAGE_BUFFER, buffer);
        }
        let t = inputs.targets;
        let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let sampled = |view: vk::ImageView, layout: vk::ImageLayout| {
            [vk::DescriptorImageInfo::default().sampler(self.sampler).image_view(view).image_layout(layout)]
        };
        let images = [
            (
                BINDING_DEPTH,
                vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                sampled(t.depth.view, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL),
            ),
            (BINDING_NORMAL, vk::DescriptorType::COMBINED_IMAGE_SAMPLER, sampled(t.gbuffer[0].view, read_only)),
            (BINDING_OBJECT_ID, vk::DescriptorType::COMBINED_IMAGE_SAMPLER, sampled(t.gbuffer[1].view, read_only)),
            (
                BINDING_OUTPUT,
                vk::DescriptorType::STORAGE_IMAGE,
                [vk::DescriptorImageInfo::default().image_view(t.color.view).image_layout(vk::ImageLayout::GENERAL)],
            ),
        ];
        let writes: Vec<vk::WriteDescriptorSet> = images
            .iter()
            .map(|(b, ty, info)| vk::WriteDescriptorSet::default().dst_set(set).dst_binding(*b).descriptor_type(*ty).image_info(info))
            .collect();
        // SAFETY: the set and everything it points at are alive and unused.
        unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
        Ok(set)
    }

    /// Record the lighting of `targets` (after the raster pass and the cluster build).
    pub fn record(&self, ctx: &Context, cmd: vk::CommandBuffer, set: vk::DescriptorSet, targets: &Targets, extent: vk::Extent2D) {
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let d = &ctx.device;
        // The colour image was last read by a copy two frames ago (same queue).
        let storage = (compute, vk::AccessFlags::SHADER_WRITE, vk::ImageLayout::GENERAL);
        image_transition(ctx, cmd, targets.color.raw, (transfer, vk::AccessFlags::empty(), vk::ImageLayout::UNDEFINED), storage);
        // SAFETY: recording state outside a render pass; everything bound is alive.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline_layout, 0, &[set], &[]);
            d.cmd_dispatch(cmd, extent.width.div_ceil(GROUP), extent.height.div_ceil(GROUP), 1);
        }
        // Left like the forward pass leaves its colour target: ready for the read-back copy.
        image_transition(
            ctx,
            cmd,
            targets.color.raw,
            storage,
            (transfer, vk::AccessFlags::TRANSFER_READ, vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
        );
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.objects.destroy(ctx);
        // SAFETY: the device is idle; null handles are ignored.
        unsafe {
            ctx.device.destroy_sampler(self.sampler, None);
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline_layout(self.pipeline_layout, None);
            ctx.device.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

impl ml_vk::Release for ComputeLighting {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
