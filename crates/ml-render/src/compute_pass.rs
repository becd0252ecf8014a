//! A compute pass over the image that writes the colour target (the compute lighting, the tone
//! map, the shadow-map view): one pipeline, its set 0 per frame slot (laid out as the shader
//! declares it; the frame's table fills it).

use crate::descriptors::{FrameSets, Resource};
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::specialization;
use crate::sync::{Use, COLOUR_TARGET, HDR_TARGET};
use ml_shaders::Shader;
use ml_vk::commands::memory_barrier;
use ml_vk::{shader, vk, Context, Image, VkError};

pub struct ComputePass {
    sets: FrameSets,
    pipeline_layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    /// The shader's work-group size, a thread per pixel: a dispatch over an image divides
    /// its size by this.
    workgroup_size: [u32; 3],
}

impl ComputePass {
    /// None yet (a pass under construction; destroying it does nothing).
    pub fn empty() -> ComputePass {
        ComputePass {
            sets: FrameSets::empty(),
            pipeline_layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            workgroup_size: [1; 3],
        }
    }

    /// The pass of `shader` (with specialization `constants`: name, value); set 0 as the
    /// shader declares it, further sets of `more_sets`.
    pub fn new(
        ctx: &Context,
        more_sets: &[vk::DescriptorSetLayout],
        (shader, constants): (&Shader, &[(&str, u32)]),
    ) -> Result<ComputePass, VkError> {
        ComputePass::with_push(ctx, more_sets, (shader, constants), 0)
    }

    /// As `new`, with `push_bytes` of push constants (0: none) that `record_runs` sets.
    pub fn with_push(
        ctx: &Context,
        more_sets: &[vk::DescriptorSetLayout],
        (shader, constants): (&Shader, &[(&str, u32)]),
        push_bytes: u32,
    ) -> Result<ComputePass, VkError> {
        let p = ComputePass {
            sets: FrameSets::new(ctx, &[(shader, vk::ShaderStageFlags::COMPUTE)], 0, FRAMES_IN_FLIGHT)?,
            pipeline_layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            workgroup_size: shader.workgroup_size,
        };
        ml_vk::build(ctx, p, |p| {
            let layouts: Vec<vk::DescriptorSetLayout> = std::iter::once(p.sets.layout.raw).chain(more_sets.iter().copied()).collect();
            let push = [vk::PushConstantRange::default().stage_flags(vk::ShaderStageFlags::COMPUTE).size(push_bytes)];
            p.pipeline_layout = shader::pipeline_layout(ctx, &layouts, if push_bytes > 0 { &push } else { &[] })?;
            p.pipeline = specialization::compute_pipeline(ctx, shader, p.pipeline_layout, constants)?;
            Ok(())
        })
    }

    /// The shader's work-group size.
    pub fn workgroup_size(&self) -> [u32; 3] {
        self.workgroup_size
    }

    /// The work groups of a dispatch over `extent` (x, y).
    pub fn groups(&self, extent: vk::Extent2D) -> (u32, u32) {
        (extent.width.div_ceil(self.workgroup_size[0]), extent.height.div_ceil(self.workgroup_size[1]))
    }

    /// Point slot `frame.slot`'s set 0 at the colour target (`out_image`, which every such
    /// pass writes) and at what the frame's table holds under the shader's names.
    pub fn bind_frame(&self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.bind_frame_with(ctx, frame, &|_| None)
    }

    /// `bind_frame`, with what `own` names (the pass's own resources) in place of the frame's.
    pub fn bind_frame_with(&self, ctx: &Context, frame: &FrameResources, own: &dyn Fn(&str) -> Option<Resource>) -> Result<(), VkError> {
        self.bind_frame_to(ctx, frame, &frame.targets.color, own)
    }

    /// `bind_frame` with `out` as `out_image` (the compute lighting's linear HDR image), and
    /// what `own` names (the pass's own resources) in place of the frame's.
    pub fn bind_frame_to(
        &self,
        ctx: &Context,
        frame: &FrameResources,
        out: &Image,
        own: &dyn Fn(&str) -> Option<Resource>,
    ) -> Result<(), VkError> {
        let out = vk::DescriptorImageInfo::default().image_view(out.view).image_layout(vk::ImageLayout::GENERAL);
        self.sets.write(ctx, frame.slot, &|name| match name {
            "out_image" => Some(Resource::Image(out)),
            _ => own(name).or_else(|| frame.resource(name)),
        })
    }

    /// How a pass that writes the colour target through this pass uses it (`Pass::uses`): as
    /// a storage image in GENERAL, every texel written.
    pub fn colour_use() -> Use {
        ComputePass::output_use(false)
    }

    /// `colour_use`, or with `hdr` the same use of the HDR target (the compute lighting's output
    /// where transparent layers are resolved after it).
    pub fn output_use(hdr: bool) -> Use {
        let name = if hdr { HDR_TARGET } else { COLOUR_TARGET };
        Use::overwriting(name, (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_WRITE), vk::ImageLayout::GENERAL)
    }

    /// Run over `extent` with slot `slot`'s set 0 and `more_sets` after it, writing `color` as a
    /// storage image (in GENERAL: the barrier before the pass, from its `colour_use`, put it
    /// there).
    pub fn record_into_colour_target(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        (slot, more_sets): (usize, &[vk::DescriptorSet]),
        color: vk::Image,
        extent: vk::Extent2D,
    ) {
        self.record_runs(ctx, cmd, slot, &[(more_sets.to_vec(), Vec::new())], (color, extent));
    }

    /// As `record_into_colour_target`, with one dispatch per run: its sets after set 0 and its
    /// push constants. Runs write distinct pixels, but synchronization validation tracks whole
    /// images: a barrier orders them.
    pub fn record_runs(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        slot: usize,
        runs: &[(Vec<vk::DescriptorSet>, Vec<u8>)],
        (_, extent): (vk::Image, vk::Extent2D),
    ) {
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        for (i, (more_sets, push)) in runs.iter().enumerate() {
            if i > 0 {
                memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (compute, vk::AccessFlags::SHADER_WRITE));
            }
            self.dispatch(ctx, cmd, slot, (more_sets, push), extent);
        }
    }

    /// One dispatch over `extent` with slot `slot`'s set 0, `more_sets` after it and `push`
    /// (empty: none); the caller orders it with what comes before and after.
    pub fn dispatch(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        slot: usize,
        (more_sets, push): (&[vk::DescriptorSet], &[u8]),
        extent: vk::Extent2D,
    ) {
        self.bind(ctx, cmd, slot, (more_sets, push));
        let (x, y) = self.groups(extent);
        // SAFETY: recording state outside a render pass; bound above.
        unsafe { ctx.device.cmd_dispatch(cmd, x, y, 1) };
    }

    /// As `dispatch`, the work groups read from `buffer` at `offset` (a
    /// VkDispatchIndirectCommand the GPU wrote; the caller orders that write before).
    pub fn dispatch_indirect(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        slot: usize,
        (more_sets, push): (&[vk::DescriptorSet], &[u8]),
        (buffer, offset): (vk::Buffer, u64),
    ) {
        self.bind(ctx, cmd, slot, (more_sets, push));
        // SAFETY: recording state outside a render pass; bound above; the buffer is alive.
        unsafe { ctx.device.cmd_dispatch_indirect(cmd, buffer, offset) };
    }

    fn bind(&self, ctx: &Context, cmd: vk::CommandBuffer, slot: usize, (more_sets, push): (&[vk::DescriptorSet], &[u8])) {
        let d = &ctx.device;
        let sets: Vec<vk::DescriptorSet> = std::iter::once(self.sets.sets[slot]).chain(more_sets.iter().copied()).collect();
        // SAFETY: recording state outside a render pass; everything bound is alive.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline_layout, 0, &sets, &[]);
            if !push.is_empty() {
                d.cmd_push_constants(cmd, self.pipeline_layout, vk::ShaderStageFlags::COMPUTE, 0, push);
            }
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        ml_vk::shader::release_pipeline(ctx, self.pipeline);
        self.sets.destroy(ctx);
        self.pipeline_layout = vk::PipelineLayout::null();
        self.pipeline = vk::Pipeline::null();
    }
}

impl ml_vk::Release for ComputePass {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
