//! The light grid's build (docs/DESIGN.md#the-light-grid), every frame on the GPU from the
//! lights at rest and the frame's motion, with no per-light CPU work and no read-back in the
//! frame:
//!
//! clear the counts → COUNT (a thread per light: move it, count it into its list — its cell,
//! or the wide lights') → SCAN (per block of 1024 lists, per 1024 blocks, over those, then
//! back down; every step but one wide) → FILL (each light
//! writes its index at its list's next place) → the shading passes walk the rows of cells
//! near their points, reading the lights at rest and moving them as the build did.
//!
//! The lights are uploaded once in the order of their cells at rest (`grid_order`): the
//! build's neighbouring threads then count into neighbouring cells, and a cell's lights lie
//! side by side for the shading — memory traffic in order instead of scattered, which is what
//! the build costs at millions of lights.
//!
//! Every light is listed exactly once, so the index list has one entry per light and can
//! never overflow; the feedback (lights listed, wide, the fullest cell) is only reported.

use super::LightGridStats;
use crate::descriptors::{FrameSets, Resource};
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::pass::{Pass, Recording, SlotReport};
use crate::report::FrameStats;
use crate::specialization::compute_pipeline;
use crate::sync::{Use, LIGHT_GRID_LISTS};
use ml_cpu::gpu_types::{FrameUniforms, LightGridFeedback, PointLight};
use ml_cpu::light_grid::{cell_budget, grid_order, LightGridShape};
use ml_vk::commands::memory_barrier;
use ml_vk::{shader, vk, Buffer, Context, VkError};

/// Lists per scan block (what light_grid_scan.comp's work group takes, light_grid.glsl
/// GRID_BLOCK).
const SCAN_BLOCK: u32 = 1024;
/// Work groups a dispatch puts along x before it adds rows along y (a device may take no more
/// than 65,535 along one axis).
const GROUPS_PER_ROW: u32 = 32_768;

/// The grid's names of its lists in the shaders (what the shading passes bind).
const CELLS: &str = "LightGridCellBuffer";
const BLOCKS: &str = "LightGridBlockBuffer";
const INDICES: &str = "LightGridIndexBuffer";
const LIGHTS: &str = "LightGridLightBuffer";
const ORDER: &str = "LightGridOrderBuffer";

pub struct LightGridBuild {
    /// The build's set per frame slot (one layout for every step: the union of the shaders').
    sets: FrameSets,
    /// Per frame slot: its lists and the build's own buffers.
    slots: Vec<GridSlot>,
    pipeline_layout: vk::PipelineLayout,
    count_pipeline: vk::Pipeline,
    /// The scan's four steps (blocks, super-blocks, their starts, the blocks' starts).
    scan_pipelines: [vk::Pipeline; 4],
    fill_pipeline: vk::Pipeline,
    /// The lights at rest in the grid's order (device-local, uploaded once; the shading
    /// moves them), their positions and radii alone (what the build reads), and per place
    /// the light's index in the scene (its spot cone's).
    lights: Buffer,
    positions: Buffer,
    order: Buffer,
    shape: LightGridShape,
    light_count: u32,
}

/// One frame slot's buffers.
struct GridSlot {
    /// Per list: its count, then its start, then its end (relative to its block).
    cells: Buffer,
    /// Per block of lists: its start in the index list (and its largest count).
    blocks: Buffer,
    /// Per 1024 blocks: the same, for the scan.
    supers: Buffer,
    /// The light indices, list after list.
    indices: Buffer,
    /// Per light: its list, from COUNT to FILL.
    list_of: Buffer,
    feedback: Buffer,
}

impl GridSlot {
    fn new(ctx: &Context, lights: u64, lists: u64) -> Result<GridSlot, VkError> {
        let slot = GridSlot {
            cells: Buffer::null(),
            blocks: Buffer::null(),
            supers: Buffer::null(),
            indices: Buffer::null(),
            list_of: Buffer::null(),
            feedback: Buffer::null(),
        };
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let gpu = gpu_allocator::MemoryLocation::GpuOnly;
        ml_vk::build(ctx, slot, |s| {
            s.cells = Buffer::new(ctx, "light grid cells", lists * 4, storage | vk::BufferUsageFlags::TRANSFER_DST, gpu)?;
            let blocks = lists.div_ceil(SCAN_BLOCK.into());
            s.blocks = Buffer::new(ctx, "light grid blocks", blocks * 8, storage, gpu)?;
            s.supers = Buffer::new(ctx, "light grid super-blocks", blocks.div_ceil(SCAN_BLOCK.into()) * 8, storage, gpu)?;
            s.indices = Buffer::new(ctx, "light grid indices", lights * 4, storage, gpu)?;
            s.list_of = Buffer::new(ctx, "light grid list of", lights * 4, storage, gpu)?;
            let feedback = size_of::<LightGridFeedback>() as u64;
            s.feedback = Buffer::new(ctx, "light grid feedback", feedback, storage, gpu_allocator::MemoryLocation::GpuToCpu)?;
            Ok(())
        })
    }

    fn feedback(&self) -> LightGridFeedback {
        bytemuck::pod_read_unaligned(&self.feedback.mapped()[..size_of::<LightGridFeedback>()])
    }
}

impl ml_vk::Release for GridSlot {
    fn release(&mut self, ctx: &Context) {
        for b in [&mut self.cells, &mut self.blocks, &mut self.supers, &mut self.indices, &mut self.list_of, &mut self.feedback] {
            b.destroy(ctx);
        }
    }
}

/// A dispatch of `groups` work groups as rows of GROUPS_PER_ROW (the shaders number them
/// row after row).
fn dispatch_grid(groups: u32) -> (u32, u32) {
    if groups <= GROUPS_PER_ROW {
        (groups.max(1), 1)
    } else {
        (GROUPS_PER_ROW, groups.div_ceil(GROUPS_PER_ROW))
    }
}

impl LightGridBuild {
    /// The build for `rest_lights`: a grid of at most `cell_budget` cells (what the device
    /// binds as one storage buffer of lists).
    pub fn new(ctx: &Context, rest_lights: &[PointLight]) -> Result<LightGridBuild, VkError> {
        let bindable = u64::from(ctx.info.limits.max_storage_buffer_range) / 4;
        let shape = LightGridShape::fit(rest_lights, cell_budget(rest_lights.len(), bindable));
        let stages = [&ml_shaders::LIGHT_GRID_BUILD_COMP, &ml_shaders::LIGHT_GRID_SCAN_COMP].map(|s| (s, vk::ShaderStageFlags::COMPUTE));
        let b = LightGridBuild {
            sets: FrameSets::new(ctx, &stages, 0, FRAMES_IN_FLIGHT)?,
            slots: Vec::new(),
            pipeline_layout: vk::PipelineLayout::null(),
            count_pipeline: vk::Pipeline::null(),
            scan_pipelines: [vk::Pipeline::null(); 4],
            fill_pipeline: vk::Pipeline::null(),
            lights: Buffer::null(),
            positions: Buffer::null(),
            order: Buffer::null(),
            shape,
            light_count: rest_lights.len() as u32,
        };
        ml_vk::build(ctx, b, |b| b.create(ctx, rest_lights))
    }

    fn create(&mut self, ctx: &Context, rest_lights: &[PointLight]) -> Result<(), VkError> {
        self.pipeline_layout = shader::pipeline_layout(ctx, &[self.sets.layout.raw], &[])?;
        let build = &ml_shaders::LIGHT_GRID_BUILD_COMP;
        self.count_pipeline = compute_pipeline(ctx, build, self.pipeline_layout, &[("FILL", 0)])?;
        self.fill_pipeline = compute_pipeline(ctx, build, self.pipeline_layout, &[("FILL", 1)])?;
        for (step, pipeline) in self.scan_pipelines.iter_mut().enumerate() {
            *pipeline = compute_pipeline(ctx, &ml_shaders::LIGHT_GRID_SCAN_COMP, self.pipeline_layout, &[("STEP", step as u32)])?;
        }
        let order = grid_order(&self.shape, rest_lights);
        let sorted: Vec<PointLight> = order.iter().map(|&i| rest_lights[i as usize]).collect();
        let positions: Vec<[f32; 4]> = sorted.iter().map(|l| l.position_radius).collect();
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let order = if order.is_empty() { vec![0] } else { order };
        self.lights = Buffer::device_local_with(ctx, "light grid lights", bytemuck::cast_slice(&sorted), storage)?;
        self.positions = Buffer::device_local_with(ctx, "light grid positions", bytemuck::cast_slice(&positions), storage)?;
        self.order = Buffer::device_local_with(ctx, "light grid order", bytemuck::cast_slice(&order), storage)?;
        for _ in 0..FRAMES_IN_FLIGHT {
            self.slots.push(GridSlot::new(ctx, u64::from(self.light_count.max(1)), self.lists())?);
        }
        Ok(())
    }

    /// Lists: every cell, then the wide lights'.
    fn lists(&self) -> u64 {
        u64::from(self.shape.cells()) + 1
    }

    /// Record the frame's build: the lists (ordered with their readers by the barriers its
    /// `uses` give) and its own buffers; afterwards the feedback is visible to the host.
    fn record_build(&self, ctx: &Context, cmd: vk::CommandBuffer, slot: usize) {
        let (own, set) = (&self.slots[slot], self.sets.sets[slot]);
        let d = &ctx.device;
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        // Its own buffers were last used by this slot's build two submissions ago.
        memory_barrier(
            ctx,
            cmd,
            (compute | vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::SHADER_WRITE | vk::AccessFlags::TRANSFER_WRITE),
            (compute | vk::PipelineStageFlags::TRANSFER, rw | vk::AccessFlags::TRANSFER_WRITE),
        );
        let light_groups = self.light_count.div_ceil(ml_shaders::LIGHT_GRID_BUILD_COMP.workgroup_size[0]);
        let blocks = self.lists().div_ceil(SCAN_BLOCK.into()) as u32;
        let supers = blocks.div_ceil(SCAN_BLOCK);
        let steps = [
            (self.count_pipeline, dispatch_grid(light_groups)),
            (self.scan_pipelines[0], dispatch_grid(blocks)),
            (self.scan_pipelines[1], dispatch_grid(supers)),
            (self.scan_pipelines[2], (1, 1)),
            (self.scan_pipelines[3], dispatch_grid(supers)),
            (self.fill_pipeline, dispatch_grid(light_groups)),
        ];
        // SAFETY: recording state outside a render pass; all bound objects are alive.
        unsafe {
            d.cmd_fill_buffer(cmd, own.cells.raw, 0, vk::WHOLE_SIZE, 0);
            memory_barrier(ctx, cmd, (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE), (compute, rw));
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline_layout, 0, &[set], &[]);
            for (i, (pipeline, (x, y))) in steps.into_iter().enumerate() {
                if i > 0 {
                    memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (compute, rw));
                }
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, pipeline);
                d.cmd_dispatch(cmd, x, y, 1);
            }
        }
        memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ));
    }

    fn release_all(&mut self, ctx: &Context) {
        for s in &mut self.slots {
            ml_vk::Release::release(s, ctx);
        }
        self.sets.destroy(ctx);
        for b in [&mut self.lights, &mut self.positions, &mut self.order] {
            b.destroy(ctx);
        }
        // SAFETY: the device is idle; null handles are ignored.
        unsafe {
            for p in [self.count_pipeline, self.fill_pipeline].into_iter().chain(self.scan_pipelines) {
                ctx.device.destroy_pipeline(p, None);
            }
            ctx.device.destroy_pipeline_layout(self.pipeline_layout, None);
        }
    }
}

impl ml_vk::Release for LightGridBuild {
    fn release(&mut self, ctx: &Context) {
        self.release_all(ctx);
    }
}

impl Pass for LightGridBuild {
    fn timer_name(&self) -> Option<&'static str> {
        Some("light grid build")
    }

    fn slot_buffers(&self, slot: usize) -> Vec<(&'static str, vk::Buffer)> {
        let s = &self.slots[slot];
        vec![(CELLS, s.cells.raw), (BLOCKS, s.blocks.raw), (INDICES, s.indices.raw), (LIGHTS, self.lights.raw), (ORDER, self.order.raw)]
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let own = &self.slots[frame.slot];
        self.sets.write(ctx, frame.slot, &|name| {
            let buffer = match name {
                "LightGridRestBuffer" => self.positions.raw,
                "LightGridListOfBuffer" => own.list_of.raw,
                "LightGridSuperBuffer" => own.supers.raw,
                "LightGridFeedbackBuffer" => own.feedback.raw,
                _ => return frame.buffer(name),
            };
            Some(Resource::Buffer(buffer))
        })
    }

    fn uses(&self) -> Vec<Use> {
        let rw = (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE);
        LIGHT_GRID_LISTS.iter().map(|&name| Use::at(name, rw, None)).collect()
    }

    fn frame_uniforms(&self, uniforms: &mut FrameUniforms, light_offset: glam::Vec3) {
        let s = &self.shape;
        uniforms.light_grid_origin = s.origin_at(light_offset).extend(1.0 / s.cell).to_array();
        uniforms.light_grid_dims = s.dims.extend(s.cells()).to_array();
        uniforms.light_grid_reach = [s.reach, s.wide as f32, 0.0, 0.0];
    }

    fn record(&self, rec: &Recording) {
        self.record_build(rec.ctx, rec.cmd, rec.slot);
    }

    fn collect(&self, slot: usize, report: &mut SlotReport, stats: &mut FrameStats) {
        let f = self.slots[slot].feedback();
        let grid = LightGridStats {
            dims: self.shape.dims.to_array(),
            cell: self.shape.cell,
            listed: f.listed,
            wide: f.wide,
            max_per_cell: f.max_count,
        };
        report.max_lights = Some(grid.heat_top());
        stats.set_feature(grid);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.release_all(ctx);
    }
}

#[cfg(test)]
mod tests {
    /// The scan's work group takes a block (four counts an invocation), the walk's GRID_BLOCK.
    #[test]
    fn scan_block_is_what_the_scan_shaders_work_group_takes() {
        assert_eq!(ml_shaders::LIGHT_GRID_SCAN_COMP.workgroup_size, [super::SCAN_BLOCK / 4, 1, 1]);
    }

    #[test]
    fn large_dispatches_come_in_rows() {
        assert_eq!(super::dispatch_grid(0), (1, 1));
        assert_eq!(super::dispatch_grid(100), (100, 1));
        assert_eq!(super::dispatch_grid(65_537), (32_768, 3));
    }
}
