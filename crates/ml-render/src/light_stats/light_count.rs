//! The light counts' pass: after the lighting, a thread per pixel walks the light loop of its
//! surface point as the lighting did (the cluster's list) and counts the lights it tests and
//! those that reach the point (light_count.glsl); a sum per 8×4 work group lands in a
//! host-visible buffer of the frame slot, which `collect` adds up. Untimed: it measures the
//! frame, it is not part of it.

use super::LightStats;
use crate::antialiasing::Antialiasing;
use crate::compute_pass::ComputePass;
use crate::descriptors::Resource;
use crate::frame_resources::{FrameResources, FRAMES_IN_FLIGHT};
use crate::pass::{FrameWork, Pass, Recording, SlotReport};
use crate::read_back::HostRead;
use crate::report::FrameStats;
use crate::scene::SceneGpu;
use crate::shading::Shading;
use crate::sync::{light_list_reads, BufferName, Use, VISIBILITY_DEPTH};
use gpu_allocator::MemoryLocation;
use ml_vk::{vk, Buffer, Context, VkError};

/// The per-group sums' name in the shaders (and in the frame's declared uses).
const LIGHT_COUNTS: BufferName = BufferName("LightCountBuffer");

pub struct LightCount {
    pass: ComputePass,
    /// Per frame slot: the work groups' sums (pixels, tested, reached), host-visible.
    counts: Vec<Buffer>,
    /// The opaque depth is the compute raster's 64-bit buffer (else the depth target).
    depth_buffer: bool,
}

impl LightCount {
    /// The counts at the opaque surfaces: with `depth_buffer` those of the compute raster's
    /// buffer (with anti-aliasing, each pixel's first sample's), else of the depth target.
    pub fn new(
        ctx: &Context,
        scene: &SceneGpu,
        shading: Shading,
        (depth_buffer, antialiasing): (bool, Antialiasing),
    ) -> Result<LightCount, VkError> {
        let mut constants = shading.lighting_constants().to_vec();
        let shader = if depth_buffer {
            constants.push(antialiasing.constant());
            &ml_shaders::LIGHT_COUNT_BUFFER_COMP
        } else {
            &ml_shaders::LIGHT_COUNT_COMP
        };
        let pass = ComputePass::new(ctx, &[scene.textures.set_layout.raw], (shader, &constants))?;
        Ok(LightCount { pass, counts: (0..FRAMES_IN_FLIGHT).map(|_| Buffer::null()).collect(), depth_buffer })
    }
}

impl Pass for LightCount {
    fn timer_name(&self) -> Option<&'static str> {
        None
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let counts = Resource::Buffer(self.counts[frame.slot].raw);
        self.pass.bind_frame_with(ctx, frame, &|name| (name == LIGHT_COUNTS.0).then_some(counts))
    }

    /// Reads the lights and lists as the lighting did, and the opaque depth (the compute
    /// raster's buffer; the depth target is ordered by the raster's render pass, whose
    /// outgoing dependency reaches compute shaders); writes its sums.
    fn uses(&self) -> Vec<Use> {
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let mut uses = light_list_reads(compute);
        if self.depth_buffer {
            uses.push(Use::buffer(VISIBILITY_DEPTH, (compute, vk::AccessFlags::SHADER_READ)));
        }
        uses.push(Use::buffer(LIGHT_COUNTS, (compute, vk::AccessFlags::SHADER_WRITE)));
        uses
    }

    fn record(&self, rec: &Recording) {
        self.pass.dispatch(rec.ctx, rec.cmd, rec.slot, (&[rec.scene.textures.set], &[]), rec.extent);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
        for b in &mut self.counts {
            b.destroy(ctx);
        }
    }

    fn frame_work(&mut self) -> Option<&mut dyn FrameWork> {
        Some(self)
    }
}

impl FrameWork for LightCount {
    fn create_slot(&mut self, ctx: &Context, slot: usize, extent: vk::Extent2D) -> Result<(), VkError> {
        self.counts[slot].destroy(ctx);
        let (x, y) = self.pass.groups(extent);
        let bytes = x as u64 * y as u64 * 16;
        self.counts[slot] = Buffer::new(ctx, "light counts", bytes, vk::BufferUsageFlags::STORAGE_BUFFER, MemoryLocation::GpuToCpu)?;
        Ok(())
    }

    fn host_reads(&self, _slot: usize) -> Vec<HostRead> {
        vec![HostRead::in_place(LIGHT_COUNTS)]
    }

    fn collect(&self, slot: usize, _: &mut SlotReport, stats: &mut FrameStats) {
        let groups: Vec<[u32; 4]> = bytemuck::pod_collect_to_vec(self.counts[slot].mapped());
        let mut sum = LightStats::default();
        for [pixels, tested, reached, _] in groups {
            sum.pixels += u64::from(pixels);
            sum.tested += u64::from(tested);
            sum.reached += u64::from(reached);
        }
        stats.set_feature(sum);
    }
}
