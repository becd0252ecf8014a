//! The GPU cluster build (docs/DESIGN.md#gpu-cluster-build): the cluster grid built by compute shaders every frame
//! from the light buffer, with no per-light CPU work and no read-back in the frame.
//!
//! Per frame: clear the counters → COUNT (1–64 invocations per light: animate it, write it for
//! shading, count it into every cluster its sphere touches) → SCAN (three steps: per-block
//! prefix sums, block totals, apply; counters become cursors; reports the entries needed) →
//! FILL (each light writes its index at its clusters' cursors) → the shading pass reads them.
//! Lights only visit the clusters under their own projected slab rectangles, so the cost
//! follows the (light, cluster) pairs, not lights × clusters.
//! Capacity: the index list has a size; the SCAN pass reports what the frame needed and cuts
//! ranges to fit when it was too small; the CPU reads that after the frame's fence and grows
//! the list for every later frame (the renderer grows it from `SlotReport`).

use crate::descriptors::{FrameSets, Resource};
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::pass::{Pass, Recording, SlotReport};
use crate::report::FrameStats;
use crate::specialization::compute_pipeline;
use crate::sync::{Use, LIGHT_LISTS};
use ml_cpu::gpu_types::{ClusterBounds, ClusterFeedback, PointLight};
use ml_vk::commands::memory_barrier;
use ml_vk::{shader, vk, Buffer, Context, VkError};

/// Clusters per scan block (cluster_scan.comp); ml_cpu::limits::MAX_CLUSTERS = SCAN_BLOCK² so the
/// block totals fit one workgroup.
const SCAN_BLOCK: u32 = 1024;

/// Invocations per light in COUNT/FILL: enough that even a few (big) lights keep ~64k
/// invocations busy, at most 64; a power of two.
fn lanes_per_light(lights: u32) -> u32 {
    (65_536 / lights.max(1)).clamp(1, 64).next_power_of_two().min(64)
}

pub struct ClusterBuild {
    /// The build's set per frame slot (one layout for every step: the union of the shaders').
    sets: FrameSets,
    /// Per frame slot: its counters, feedback and scan blocks.
    frames: Vec<GpuClusterFrame>,
    pipeline_layout: vk::PipelineLayout,
    bounds_pipeline: vk::Pipeline,
    count_pipeline: vk::Pipeline,
    /// The three steps of the prefix sum (block scans, block totals, apply).
    scan_pipelines: [vk::Pipeline; 3],
    fill_pipeline: vk::Pipeline,
    lanes: u32,
    /// Lights at rest, uploaded once (device-local); the COUNT pass animates them.
    pub rest_lights: Buffer,
    /// Every cluster's view-space box, rebuilt by `compute_bounds`.
    pub bounds: Buffer,
    light_count: u32,
    cluster_count: u32,
}

/// Per frame in flight: the counters/cursors, the feedback the CPU reads.
struct GpuClusterFrame {
    counters: Buffer,
    feedback: Buffer,
    /// Per scan block: its total and largest count, then its offset.
    scan_blocks: Buffer,
}

impl GpuClusterFrame {
    fn feedback(&self) -> ClusterFeedback {
        bytemuck::pod_read_unaligned(&self.feedback.mapped()[..size_of::<ClusterFeedback>()])
    }

    fn destroy(&mut self, ctx: &Context) {
        self.counters.destroy(ctx);
        self.feedback.destroy(ctx);
        self.scan_blocks.destroy(ctx);
    }
}

impl ClusterBuild {
    pub fn new(ctx: &Context, rest_lights: &[PointLight], cluster_count: usize) -> Result<ClusterBuild, VkError> {
        let steps = [&ml_shaders::CLUSTER_BOUNDS_COMP, &ml_shaders::CLUSTER_BUILD_COMP, &ml_shaders::CLUSTER_SCAN_COMP];
        let stages: Vec<(&ml_shaders::Shader, vk::ShaderStageFlags)> = steps.iter().map(|&s| (s, vk::ShaderStageFlags::COMPUTE)).collect();
        let b = ClusterBuild {
            sets: FrameSets::new(ctx, &stages, 0, FRAMES_IN_FLIGHT)?,
            frames: Vec::new(),
            pipeline_layout: vk::PipelineLayout::null(),
            bounds_pipeline: vk::Pipeline::null(),
            count_pipeline: vk::Pipeline::null(),
            scan_pipelines: [vk::Pipeline::null(); 3],
            fill_pipeline: vk::Pipeline::null(),
            lanes: lanes_per_light(rest_lights.len() as u32),
            rest_lights: Buffer::null(),
            bounds: Buffer::null(),
            light_count: rest_lights.len() as u32,
            cluster_count: cluster_count as u32,
        };
        ml_vk::build(ctx, b, |b| b.create(ctx, rest_lights))
    }

    fn create(&mut self, ctx: &Context, rest_lights: &[PointLight]) -> Result<(), VkError> {
        self.pipeline_layout = shader::pipeline_layout(ctx, &[self.sets.layout.raw], &[])?;
        self.bounds_pipeline = compute_pipeline(ctx, &ml_shaders::CLUSTER_BOUNDS_COMP, self.pipeline_layout, &[])?;
        let build = &ml_shaders::CLUSTER_BUILD_COMP;
        self.count_pipeline = compute_pipeline(ctx, build, self.pipeline_layout, &[("FILL", 0), ("LANES", self.lanes)])?;
        self.fill_pipeline = compute_pipeline(ctx, build, self.pipeline_layout, &[("FILL", 1), ("LANES", self.lanes)])?;
        for (step, pipeline) in self.scan_pipelines.iter_mut().enumerate() {
            *pipeline = compute_pipeline(ctx, &ml_shaders::CLUSTER_SCAN_COMP, self.pipeline_layout, &[("STEP", step as u32)])?;
        }
        self.rest_lights =
            Buffer::device_local_with(ctx, "lights at rest", bytemuck::cast_slice(rest_lights), vk::BufferUsageFlags::STORAGE_BUFFER)?;
        self.bounds = Buffer::new(
            ctx,
            "cluster bounds",
            (self.cluster_count as usize * size_of::<ClusterBounds>()) as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            gpu_allocator::MemoryLocation::GpuOnly,
        )?;
        for _ in 0..FRAMES_IN_FLIGHT {
            self.frames.push(self.frame_resources(ctx)?);
        }
        Ok(())
    }

    /// Rebuild every cluster's box (when projection or image size change) with the grid in
    /// `set`'s uniforms, and wait for it.
    fn compute_bounds(&self, ctx: &Context, set: vk::DescriptorSet) -> Result<(), VkError> {
        ml_vk::commands::one_shot(ctx, |cmd| {
            // SAFETY: recording state; all bound objects are alive.
            unsafe {
                ctx.device.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.bounds_pipeline);
                ctx.device.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline_layout, 0, &[set], &[]);
                let [groups, ..] = ml_shaders::CLUSTER_BOUNDS_COMP.groups([self.cluster_count, 1, 1]);
                ctx.device.cmd_dispatch(cmd, groups, 1, 1);
            }
            let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
            memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (compute, vk::AccessFlags::SHADER_READ));
        })
    }

    /// Record the frame's build: the lights, ranges and index list (ordered with their readers
    /// by the barriers its `uses` give), and its own buffers; afterwards the feedback is
    /// visible to the host.
    fn record_build(&self, ctx: &Context, cmd: vk::CommandBuffer, slot: usize) {
        let (frame, set) = (&self.frames[slot], self.sets.sets[slot]);
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
        let build_group = ml_shaders::CLUSTER_BUILD_COMP.workgroup_size[0];
        let light_groups = (self.light_count as u64 * self.lanes as u64).div_ceil(build_group as u64) as u32;
        let blocks = self.cluster_count.div_ceil(SCAN_BLOCK);
        let steps = [
            (self.count_pipeline, light_groups),
            (self.scan_pipelines[0], blocks),
            (self.scan_pipelines[1], 1),
            (self.scan_pipelines[2], blocks),
            (self.fill_pipeline, light_groups),
        ];
        // SAFETY: recording state outside a render pass; all bound objects are alive.
        unsafe {
            d.cmd_fill_buffer(cmd, frame.counters.raw, 0, vk::WHOLE_SIZE, 0);
            memory_barrier(ctx, cmd, (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE), (compute, rw));
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline_layout, 0, &[set], &[]);
            for (i, (pipeline, groups)) in steps.into_iter().enumerate() {
                if i > 0 {
                    memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (compute, rw));
                }
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, pipeline);
                d.cmd_dispatch(cmd, groups, 1, 1);
            }
        }
        memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ));
    }

    /// A frame slot's build buffers.
    fn frame_resources(&self, ctx: &Context) -> Result<GpuClusterFrame, VkError> {
        let frame = GpuClusterFrame { counters: Buffer::null(), feedback: Buffer::null(), scan_blocks: Buffer::null() };
        ml_vk::build(ctx, frame, |frame| {
            frame.counters = Buffer::new(
                ctx,
                "cluster counters",
                self.cluster_count as u64 * 4,
                vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                gpu_allocator::MemoryLocation::GpuOnly,
            )?;
            frame.feedback = Buffer::new(
                ctx,
                "cluster feedback",
                size_of::<ClusterFeedback>() as u64,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                gpu_allocator::MemoryLocation::GpuToCpu,
            )?;
            frame.scan_blocks = Buffer::new(
                ctx,
                "cluster scan blocks",
                self.cluster_count.div_ceil(SCAN_BLOCK) as u64 * 8,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                gpu_allocator::MemoryLocation::GpuOnly,
            )?;
            Ok(())
        })
    }

    fn release_all(&mut self, ctx: &Context) {
        for f in &mut self.frames {
            f.destroy(ctx);
        }
        self.sets.destroy(ctx);
        self.rest_lights.destroy(ctx);
        self.bounds.destroy(ctx);
        // SAFETY: the device is idle; null handles are ignored.
        unsafe {
            for p in [self.bounds_pipeline, self.count_pipeline, self.fill_pipeline].into_iter().chain(self.scan_pipelines) {
                ctx.device.destroy_pipeline(p, None);
            }
            ctx.device.destroy_pipeline_layout(self.pipeline_layout, None);
        }
    }
}

impl ml_vk::Release for ClusterBuild {
    fn release(&mut self, ctx: &Context) {
        self.release_all(ctx);
    }
}

impl Pass for ClusterBuild {
    fn timer_name(&self) -> Option<&'static str> {
        Some("cluster build")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let own = &self.frames[frame.slot];
        self.sets.write(ctx, frame.slot, &|name| {
            let buffer = match name {
                "RestLightBuffer" => self.rest_lights.raw,
                "BoundsBuffer" => self.bounds.raw,
                "CounterBuffer" => own.counters.raw,
                "FeedbackBuffer" => own.feedback.raw,
                "BlockBuffer" => own.scan_blocks.raw,
                _ => return frame.buffer(name),
            };
            Some(Resource::Buffer(buffer))
        })
    }

    fn uses(&self) -> Vec<Use> {
        let rw = (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE);
        LIGHT_LISTS.iter().map(|&name| Use::at(name, rw, None)).collect()
    }

    fn record(&self, rec: &Recording) {
        self.record_build(rec.ctx, rec.cmd, rec.slot);
    }

    fn collect(&self, slot: usize, report: &mut SlotReport, _: &mut FrameStats) {
        let f = self.frames[slot].feedback();
        report.index_entries = Some(f.needed as usize);
        report.max_lights = Some(f.max_count);
        report.overflowed = f.overflowed != 0;
    }

    /// The boxes depend on projection and size only: built with slot 0's uniforms.
    fn projection_changed(&mut self, ctx: &Context) -> Result<(), VkError> {
        self.compute_bounds(ctx, self.sets.sets[0])
    }

    fn destroy(&mut self, ctx: &Context) {
        self.release_all(ctx);
    }
}

impl ml_vk::Release for GpuClusterFrame {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}

#[cfg(test)]
mod tests {
    /// Step 0 of the scan runs a work group per block, an invocation per cluster, and step 1
    /// one group over the blocks' totals: the block is the scan shader's work group, and
    /// MAX_CLUSTERS at most SCAN_BLOCK².
    #[test]
    fn scan_block_is_the_scan_shaders_work_group() {
        assert_eq!(ml_shaders::CLUSTER_SCAN_COMP.workgroup_size, [super::SCAN_BLOCK, 1, 1]);
        assert!(u64::from(super::SCAN_BLOCK).pow(2) >= ml_cpu::limits::MAX_CLUSTERS);
    }
}
