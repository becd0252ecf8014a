//! The light grid's build (docs/DESIGN.md#the-light-grid), every frame on the GPU from the
//! lights at rest and the frame's motion, with no per-light CPU work and no read-back in the
//! frame:
//!
//! the marks (`light_grid_mark`: the cells the frame's surface points will walk; every cell
//! where the technique has no surfaces before its lighting) → SCAN of the marks (each marked
//! cell gets a list after the wide lights' list 0) → COUNT (a thread per light: move it, find
//! its list — list 0 if wide, else its cell's if marked, else none: no pixel tests it — and
//! count it there) → SCAN of the counts → FILL (each kept light writes itself, moved, at its
//! list's next place) → the shading passes walk the rows of cells near their points and read
//! the lists' lights in order.
//!
//! The lights are uploaded once in the order of their cells at rest (`grid_order`): the
//! build's neighbouring threads then count into neighbouring cells. Only the kept lights are
//! written: the lights far from every visible surface cost the frame one read of their
//! position.
//!
//! Every kept light is listed exactly once, so the lists hold at most one entry per light
//! and can never overflow; the feedback (lights listed, wide, the fullest cell, the marked
//! cells) is only reported.

use super::LightGridStats;
use crate::descriptors::{FrameSets, Resource};
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::pass::{FrameWork, Pass, Recording, SlotReport};
use crate::read_back::HostRead;
use crate::report::FrameStats;
use crate::specialization::compute_pipeline;
use crate::sync::{BufferName, Use, LIGHT_GRID_LISTS, LIGHT_GRID_OCCUPANCY};
use bytemuck::Zeroable;
use ml_cpu::gpu_types::{FrameUniforms, LightGridDispatch, LightGridFeedback, PointLight};
use ml_cpu::light_grid::{bindable_cells, cell_budget, grid_order, LightGridShape};
use ml_vk::commands::memory_barrier;
use ml_vk::{shader, vk, Buffer, Context, VkError};

/// Counts per scan block (what light_grid_scan.comp's work group takes).
const SCAN_BLOCK: u32 = 1024;
/// Work groups a dispatch puts along x before it adds rows along y (a device may take no more
/// than 65,535 along one axis; light_grid_scan.comp GROUPS_PER_ROW).
const GROUPS_PER_ROW: u32 = 32_768;
/// Cells per word of marks.
const CELLS_PER_WORD: u64 = 32;

pub struct LightGridBuild {
    /// The build's set per frame slot (one layout for every step: the union of the shaders').
    sets: FrameSets,
    /// Per frame slot: its lists and the build's own buffers.
    slots: Vec<GridSlot>,
    pipeline_layout: vk::PipelineLayout,
    count_pipeline: vk::Pipeline,
    fill_pipeline: vk::Pipeline,
    /// The scans' three steps (blocks' totals, their starts, the counts' starts), of the marks
    /// and of the lists' counts.
    mark_scan: [vk::Pipeline; 3],
    list_scan: [vk::Pipeline; 3],
    /// The lights at rest in the grid's order (device-local, uploaded once; the wide lights
    /// last), their positions alone, packed (what COUNT reads of every light: 12 bytes), and
    /// per place the light's index in the scene (its spot cone's).
    lights: Buffer,
    positions: Buffer,
    order: Buffer,
    shape: LightGridShape,
    light_count: u32,
    /// A marks pass (`LightGridMark`) runs before the build; else the build marks every cell.
    marked: bool,
}

/// One frame slot's buffers.
struct GridSlot {
    /// Per list: its count, then its start (FILL's cursor), then its end (what the walk
    /// reads).
    lists: Buffer,
    /// Per 32 cells: their marks and the list of the first marked one.
    occupancy: Buffer,
    /// Per block of counts: its total, then its start (and its largest count).
    blocks: Buffer,
    /// Per work group of COUNT: its kept lights (place, list), and how many.
    kept: Buffer,
    kept_count: Buffer,
    /// The lists: the lights, moved, list after list (position and radius; colour); their
    /// indices in the scene.
    positions: Buffer,
    colors: Buffer,
    indices: Buffer,
    /// The lists this frame and the work groups of their scan (indirect dispatches).
    dispatch: Buffer,
    feedback: Buffer,
}

/// The feedback's shader block (light_grid_scan.comp).
const FEEDBACK: BufferName = BufferName("LightGridFeedbackBuffer");

impl GridSlot {
    fn new(ctx: &Context, lights: u64, cells: u64) -> Result<GridSlot, VkError> {
        let slot = GridSlot {
            lists: Buffer::null(),
            occupancy: Buffer::null(),
            blocks: Buffer::null(),
            kept: Buffer::null(),
            kept_count: Buffer::null(),
            positions: Buffer::null(),
            colors: Buffer::null(),
            indices: Buffer::null(),
            dispatch: Buffer::null(),
            feedback: Buffer::null(),
        };
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let gpu = gpu_allocator::MemoryLocation::GpuOnly;
        let lists = cells + 1;
        let group = u64::from(ml_shaders::LIGHT_GRID_BUILD_COMP.workgroup_size[0]);
        let light_groups = lights.div_ceil(group);
        ml_vk::build(ctx, slot, |s| {
            s.lists = Buffer::new(ctx, "light grid lists", lists * 4, storage, gpu)?;
            let words = cells.div_ceil(CELLS_PER_WORD);
            s.occupancy = Buffer::new(ctx, "light grid marks", words * 8, storage | vk::BufferUsageFlags::TRANSFER_DST, gpu)?;
            let blocks = lists.div_ceil(SCAN_BLOCK.into());
            s.blocks = Buffer::new(ctx, "light grid blocks", blocks * 8, storage, gpu)?;
            s.kept = Buffer::new(ctx, "light grid kept lights", light_groups * group * 8, storage, gpu)?;
            s.kept_count = Buffer::new(ctx, "light grid kept counts", light_groups * 4, storage, gpu)?;
            s.positions = Buffer::new(ctx, "light grid positions", lights * 16, storage, gpu)?;
            s.colors = Buffer::new(ctx, "light grid colours", lights * 16, storage, gpu)?;
            s.indices = Buffer::new(ctx, "light grid indices", lights * 4, storage, gpu)?;
            let dispatch = size_of::<LightGridDispatch>() as u64;
            s.dispatch = Buffer::new(ctx, "light grid dispatch", dispatch, storage | vk::BufferUsageFlags::INDIRECT_BUFFER, gpu)?;
            let feedback = size_of::<LightGridFeedback>() as u64;
            s.feedback = Buffer::new(ctx, "light grid feedback", feedback, storage, gpu_allocator::MemoryLocation::GpuToCpu)?;
            Ok(())
        })
    }

    fn feedback(&self) -> LightGridFeedback {
        bytemuck::pod_read_unaligned(&self.feedback.mapped()[..size_of::<LightGridFeedback>()])
    }

    fn buffers(&mut self) -> [&mut Buffer; 10] {
        [
            &mut self.lists,
            &mut self.occupancy,
            &mut self.blocks,
            &mut self.kept,
            &mut self.kept_count,
            &mut self.positions,
            &mut self.colors,
            &mut self.indices,
            &mut self.dispatch,
            &mut self.feedback,
        ]
    }
}

impl ml_vk::Release for GridSlot {
    fn release(&mut self, ctx: &Context) {
        for b in self.buffers() {
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

/// One step of the build: a pipeline and its work groups.
#[derive(Clone, Copy)]
enum Groups {
    Direct(u32, u32),
    /// From the slot's dispatch buffer at this offset (written by the marks' scan).
    Indirect(u64),
}

impl LightGridBuild {
    /// The build for `rest_lights`: a grid of at most `cell_budget` cells (what the device
    /// binds as one storage buffer of lists); `marked`: a marks pass runs before it.
    pub fn new(ctx: &Context, rest_lights: &[PointLight], marked: bool) -> Result<LightGridBuild, VkError> {
        let bindable = bindable_cells(ctx.info.limits.max_storage_buffer_range);
        let shape = LightGridShape::fit(rest_lights, cell_budget(rest_lights.len(), bindable));
        let stages = [&ml_shaders::LIGHT_GRID_BUILD_COMP, &ml_shaders::LIGHT_GRID_SCAN_COMP].map(|s| (s, vk::ShaderStageFlags::COMPUTE));
        let b = LightGridBuild {
            sets: FrameSets::new(ctx, &stages, 0, FRAMES_IN_FLIGHT)?,
            slots: Vec::new(),
            pipeline_layout: vk::PipelineLayout::null(),
            count_pipeline: vk::Pipeline::null(),
            fill_pipeline: vk::Pipeline::null(),
            mark_scan: [vk::Pipeline::null(); 3],
            list_scan: [vk::Pipeline::null(); 3],
            lights: Buffer::null(),
            positions: Buffer::null(),
            order: Buffer::null(),
            shape,
            light_count: rest_lights.len() as u32,
            marked,
        };
        ml_vk::build(ctx, b, |b| b.create(ctx, rest_lights))
    }

    fn create(&mut self, ctx: &Context, rest_lights: &[PointLight]) -> Result<(), VkError> {
        self.pipeline_layout = shader::pipeline_layout(ctx, &[self.sets.layout.raw], &[])?;
        let build = &ml_shaders::LIGHT_GRID_BUILD_COMP;
        self.count_pipeline = compute_pipeline(ctx, build, self.pipeline_layout, &[("STEP", 0)])?;
        self.fill_pipeline = compute_pipeline(ctx, build, self.pipeline_layout, &[("STEP", 1)])?;
        for (source, pipelines) in [(1, &mut self.mark_scan[..]), (0, &mut self.list_scan[..])] {
            for (step, pipeline) in pipelines.iter_mut().enumerate() {
                let constants = [("STEP", step as u32), ("SOURCE", source)];
                *pipeline = compute_pipeline(ctx, &ml_shaders::LIGHT_GRID_SCAN_COMP, self.pipeline_layout, &constants)?;
            }
        }
        // A one-element stand-in where there are no lights (a buffer has a size).
        let guard = |n: usize| n.max(1);
        let order = grid_order(&self.shape, rest_lights);
        let mut sorted: Vec<PointLight> = order.iter().map(|&i| rest_lights[i as usize]).collect();
        sorted.resize(guard(sorted.len()), PointLight::zeroed());
        let positions: Vec<f32> = sorted.iter().flat_map(|l| l.position_radius[..3].to_vec()).collect();
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let mut order = order;
        order.resize(guard(order.len()), 0);
        self.lights = Buffer::device_local_with(ctx, "light grid lights at rest", bytemuck::cast_slice(&sorted), storage)?;
        self.positions = Buffer::device_local_with(ctx, "light grid positions", bytemuck::cast_slice(&positions), storage)?;
        self.order = Buffer::device_local_with(ctx, "light grid order", bytemuck::cast_slice(&order), storage)?;
        for _ in 0..FRAMES_IN_FLIGHT {
            self.slots.push(GridSlot::new(ctx, u64::from(self.light_count.max(1)), u64::from(self.shape.cells()))?);
        }
        Ok(())
    }

    /// Record the frame's build: the lists (ordered with their readers by the barriers its
    /// `uses` give) and its own buffers.
    fn record_build(&self, ctx: &Context, cmd: vk::CommandBuffer, slot: usize) {
        let (own, set) = (&self.slots[slot], self.sets.sets[slot]);
        let d = &ctx.device;
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let indirect = vk::PipelineStageFlags::DRAW_INDIRECT;
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        // Its own buffers were last used by this slot's build two submissions ago.
        memory_barrier(
            ctx,
            cmd,
            (compute | indirect, vk::AccessFlags::SHADER_WRITE),
            (compute | indirect, rw | vk::AccessFlags::INDIRECT_COMMAND_READ),
        );
        let light_groups = self.light_count.div_ceil(ml_shaders::LIGHT_GRID_BUILD_COMP.workgroup_size[0]);
        let words = u64::from(self.shape.cells()).div_ceil(CELLS_PER_WORD);
        let word_blocks = dispatch_grid(words.div_ceil(SCAN_BLOCK.into()) as u32);
        let list_blocks = Groups::Indirect(std::mem::offset_of!(LightGridDispatch, block_groups) as u64);
        let (lx, ly) = dispatch_grid(light_groups);
        let steps = [
            (self.mark_scan[0], Groups::Direct(word_blocks.0, word_blocks.1)),
            (self.mark_scan[1], Groups::Direct(1, 1)),
            (self.mark_scan[2], Groups::Direct(word_blocks.0, word_blocks.1)),
            (self.count_pipeline, Groups::Direct(lx, ly)),
            (self.list_scan[0], list_blocks),
            (self.list_scan[1], Groups::Direct(1, 1)),
            (self.list_scan[2], list_blocks),
            (self.fill_pipeline, Groups::Direct(lx, ly)),
        ];
        // SAFETY: recording state outside a render pass; all bound objects are alive.
        unsafe {
            if !self.marked {
                // No surfaces before the lighting: every cell is marked.
                d.cmd_fill_buffer(cmd, own.occupancy.raw, 0, vk::WHOLE_SIZE, u32::MAX);
                memory_barrier(ctx, cmd, (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE), (compute, rw));
            }
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline_layout, 0, &[set], &[]);
            for (i, (pipeline, groups)) in steps.into_iter().enumerate() {
                if i > 0 {
                    // An indirect dispatch also waits for its work groups' count.
                    let to = match groups {
                        Groups::Direct(..) => (compute, rw),
                        Groups::Indirect(_) => (compute | indirect, rw | vk::AccessFlags::INDIRECT_COMMAND_READ),
                    };
                    memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), to);
                }
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, pipeline);
                match groups {
                    Groups::Direct(x, y) => d.cmd_dispatch(cmd, x, y, 1),
                    Groups::Indirect(offset) => d.cmd_dispatch_indirect(cmd, own.dispatch.raw, offset),
                }
            }
        }
    }

    fn release_all(&mut self, ctx: &Context) {
        for s in &mut self.slots {
            ml_vk::Release::release(s, ctx);
        }
        self.sets.destroy(ctx);
        for b in [&mut self.lights, &mut self.positions, &mut self.order] {
            b.destroy(ctx);
        }
        for p in [self.count_pipeline, self.fill_pipeline].into_iter().chain(self.mark_scan).chain(self.list_scan) {
            ml_vk::shader::release_pipeline(ctx, p);
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

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let own = &self.slots[frame.slot];
        self.sets.write(ctx, frame.slot, &|name| {
            let buffer = match name {
                "LightGridRestBuffer" => self.positions.raw,
                "LightGridRestLightBuffer" => self.lights.raw,
                "LightGridOrderBuffer" => self.order.raw,
                "LightGridBlockBuffer" => own.blocks.raw,
                "LightGridKeptBuffer" => own.kept.raw,
                "LightGridKeptCountBuffer" => own.kept_count.raw,
                "LightGridDispatchBuffer" => own.dispatch.raw,
                n if n == FEEDBACK.0 => own.feedback.raw,
                _ => return frame.resource(name),
            };
            Some(Resource::Buffer(buffer))
        })
    }

    fn uses(&self) -> Vec<Use> {
        let rw = (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE);
        let mut uses: Vec<Use> = LIGHT_GRID_LISTS.iter().map(|&name| Use::buffer(name, rw)).collect();
        // The marks: read (and their words' lists written) after the marks pass, or all set here.
        let marks = if self.marked {
            rw
        } else {
            let stages = vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER;
            (stages, rw.1 | vk::AccessFlags::TRANSFER_WRITE)
        };
        uses.push(Use::buffer(LIGHT_GRID_OCCUPANCY, marks));
        uses.push(Use::buffer(FEEDBACK, (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_WRITE)));
        uses
    }

    fn record(&self, rec: &Recording) {
        self.record_build(rec.ctx, rec.cmd, rec.slot);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.release_all(ctx);
    }

    fn frame_work(&mut self) -> Option<&mut dyn FrameWork> {
        Some(self)
    }
}

impl FrameWork for LightGridBuild {
    fn slot_buffers(&self, slot: usize) -> Vec<(BufferName, vk::Buffer)> {
        let s = &self.slots[slot];
        let [ends, positions, colors, indices] = LIGHT_GRID_LISTS;
        vec![
            (ends, s.lists.raw),
            (positions, s.positions.raw),
            (colors, s.colors.raw),
            (indices, s.indices.raw),
            (LIGHT_GRID_OCCUPANCY, s.occupancy.raw),
        ]
    }

    /// The feedback, where the scan wrote it (host-visible).
    fn host_reads(&self, _slot: usize) -> Vec<HostRead> {
        vec![HostRead::in_place(FEEDBACK)]
    }

    fn frame_uniforms(&self, uniforms: &mut FrameUniforms, light_offset: glam::Vec3) {
        let s = &self.shape;
        uniforms.light_grid_origin = s.origin_at(light_offset).extend(1.0 / s.cell).to_array();
        uniforms.light_grid_dims = s.dims.extend(s.cells()).to_array();
        uniforms.light_grid_reach = [s.reach, s.wide as f32, 0.0, 0.0];
    }

    fn collect(&self, slot: usize, report: &mut SlotReport, stats: &mut FrameStats) {
        let f = self.slots[slot].feedback();
        let grid = LightGridStats {
            dims: self.shape.dims.to_array(),
            cell: self.shape.cell,
            cells_marked: f.cells_marked,
            lights: self.light_count,
            listed: f.listed,
            wide: f.wide,
            max_per_cell: f.max_count,
        };
        report.max_lights = Some(grid.heat_top());
        stats.set_feature(grid);
    }
}

#[cfg(test)]
mod tests {
    /// The scan's work group takes a block (four counts an invocation).
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
