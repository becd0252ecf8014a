//! The depth pyramid of the late culling phase (depth_pyramid_pass.glsl): level 0 the early
//! raster's depth — the hardware raster's depth image, or the compute raster's 64-bit buffer
//! read where it lies — reduced 2×2 to the farthest value, each level the one below it reduced
//! again (up to six levels a dispatch, depth_pyramid_levels.comp), into one storage buffer (a
//! frame target, made again with the others). A buffer rather than a mipmapped image: plain
//! loads, no per-level views, and the same answers on every driver.

use crate::antialiasing::Antialiasing;
use crate::descriptors::FrameSets;
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::pass::{Pass, Recording};
use crate::specialization::compute_pipeline;
use crate::sync::{Use, DEPTH_PYRAMID, VISIBILITY_DEPTH};
use crate::targets::{depth_pyramid_level, depth_pyramid_shape};
use ml_shaders::Shader;
use ml_vk::commands::memory_barrier;
use ml_vk::{shader, vk, Context, VkError};

/// The levels above the first: a work group's 32×32 texels of the first level it makes, and
/// on to one texel.
const LEVELS: &Shader = &ml_shaders::DEPTH_PYRAMID_LEVELS_COMP;
const LEVELS_A_DISPATCH: u32 = 6;

pub struct DepthPyramid {
    sets: FrameSets,
    pipeline_layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    /// The levels above the first, from the one below each (depth_pyramid_levels.comp).
    level_sets: FrameSets,
    level_layout: vk::PipelineLayout,
    level_pipeline: vk::Pipeline,
    /// Its dispatches cover a level by the shader's work groups.
    shader: &'static Shader,
    /// It reads the compute raster's 64-bit buffer (else the depth image).
    from_buffer: bool,
}

impl DepthPyramid {
    /// The pyramid of the depth image, or with `from_buffer` of the compute raster's buffer
    /// (its samples: `antialiasing`).
    pub fn new(ctx: &Context, from_buffer: bool, antialiasing: Antialiasing) -> Result<DepthPyramid, VkError> {
        let shader = match (from_buffer, antialiasing) {
            (false, _) => &ml_shaders::DEPTH_PYRAMID_COMP,
            (true, Antialiasing::Off) => &ml_shaders::DEPTH_PYRAMID_BUFFER_COMP,
            // Several samples a pixel: read as pairs, a work group's pixels together.
            (true, _) => &ml_shaders::DEPTH_PYRAMID_SAMPLES_COMP,
        };
        let p = DepthPyramid {
            sets: FrameSets::new(ctx, &[(shader, vk::ShaderStageFlags::COMPUTE)], 0, FRAMES_IN_FLIGHT)?,
            pipeline_layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            level_sets: FrameSets::new(ctx, &[(LEVELS, vk::ShaderStageFlags::COMPUTE)], 0, FRAMES_IN_FLIGHT)?,
            level_layout: vk::PipelineLayout::null(),
            level_pipeline: vk::Pipeline::null(),
            shader,
            from_buffer,
        };
        ml_vk::build(ctx, p, |p| {
            let push = [vk::PushConstantRange::default().stage_flags(vk::ShaderStageFlags::COMPUTE).size(16)];
            p.pipeline_layout = shader::pipeline_layout(ctx, &[p.sets.layout.raw], &push)?;
            let constants = if from_buffer { vec![antialiasing.constant()] } else { Vec::new() };
            p.pipeline = compute_pipeline(ctx, shader, p.pipeline_layout, &constants)?;
            p.level_layout = shader::pipeline_layout(ctx, &[p.level_sets.layout.raw], &push)?;
            p.level_pipeline = compute_pipeline(ctx, LEVELS, p.level_layout, &[])?;
            Ok(())
        })
    }
}

impl Pass for DepthPyramid {
    fn timer_name(&self) -> Option<&'static str> {
        Some("depth pyramid")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.sets.write(ctx, frame.slot, &|name| frame.resource(name))?;
        self.level_sets.write(ctx, frame.slot, &|name| frame.resource(name))
    }

    /// Its levels, written (and read, each from the one before) in compute; the culling reads
    /// them, the late phase this frame's, the early one the last frame's on this slot. And the
    /// compute raster's 64-bit buffer it reads.
    fn uses(&self) -> Vec<Use> {
        let rw = (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE);
        let mut uses = vec![Use::buffer(DEPTH_PYRAMID, rw)];
        if self.from_buffer {
            uses.push(Use::buffer(VISIBILITY_DEPTH, (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_READ)));
        }
        uses
    }

    /// After the early raster: the hardware raster's render pass makes its depth image
    /// visible to compute; the compute raster's buffer is a declared use.
    fn record(&self, rec: &Recording) {
        let (ctx, cmd) = (rec.ctx, rec.cmd);
        let d = &ctx.device;
        let (_, levels) = depth_pyramid_shape(rec.extent);
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        // SAFETY: recording state outside a render pass; everything bound is alive.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline_layout, 0, &[self.sets.sets[rec.slot]], &[]);
            let push = [rec.extent.width, rec.extent.height, 0, 0];
            d.cmd_push_constants(cmd, self.pipeline_layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::cast_slice(&push));
            let size = depth_pyramid_level(rec.extent, 0);
            let [x, y, _] = self.shader.groups([size.width, size.height, 1]);
            d.cmd_dispatch(cmd, x, y, 1);
            if levels > 1 {
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.level_pipeline);
                let set = [self.level_sets.sets[rec.slot]];
                d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.level_layout, 0, &set, &[]);
            }
            for first in (1..levels).step_by(LEVELS_A_DISPATCH as usize) {
                memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (compute, rw));
                let end = (first + LEVELS_A_DISPATCH).min(levels);
                let push = [first, rec.extent.width, rec.extent.height, end];
                d.cmd_push_constants(cmd, self.level_layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::cast_slice(&push));
                // A work group makes 2×2 texels a thread of the first level.
                let size = depth_pyramid_level(rec.extent, first);
                let [x, y, _] = LEVELS.groups([size.width.div_ceil(2), size.height.div_ceil(2), 1]);
                d.cmd_dispatch(cmd, x, y, 1);
            }
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        ml_vk::shader::release_pipeline(ctx, self.pipeline);
        ml_vk::shader::release_pipeline(ctx, self.level_pipeline);
        self.pipeline = vk::Pipeline::null();
        self.pipeline_layout = vk::PipelineLayout::null();
        self.level_pipeline = vk::Pipeline::null();
        self.level_layout = vk::PipelineLayout::null();
        self.sets.destroy(ctx);
        self.level_sets.destroy(ctx);
    }
}

impl ml_vk::Release for DepthPyramid {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
