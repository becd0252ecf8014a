//! Auto exposure's meter (`--exposure auto`; docs/DESIGN.md#exposure): the last pass of a
//! frame reads the finished 8-bit image back into linear luminance and sums log2 luminance per
//! 8×8 work group (exposure_meter.comp); the sums are copied to the host at the frame's end, and
//! `collect` adds them up into the frame's log-average luminance, which the renderer turns into
//! the next frame's EV.

use crate::compute_pass::ComputePass;
use crate::descriptors::Resource;
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::pass::{FrameWork, Pass, Recording, SlotReport};
use crate::read_back::{HostRead, ReadBack};
use crate::report::FrameStats;
use crate::sync::{BufferName, Use, COLOUR_TARGET};
use gpu_allocator::MemoryLocation;
use ml_vk::{vk, Buffer, Context, VkError};

/// The sums' shader block.
const SUMS: BufferName = BufferName("ExposureMeterBuffer");

pub struct ExposureMeter {
    pass: ComputePass,
    /// Per frame slot: the work groups' sums on the GPU, their copy for the host, and the
    /// groups they hold (made for the slot's image size when the slot is bound).
    sums: Vec<Buffer>,
    readback: ReadBack,
    groups: Vec<u32>,
}

impl ExposureMeter {
    /// The meter of frames shaded with pbr's tone map (`aces`) or without.
    pub fn new(ctx: &Context, aces: bool) -> Result<ExposureMeter, VkError> {
        let curve = [("MODEL_PBR", u32::from(aces))];
        Ok(ExposureMeter {
            pass: ComputePass::new(ctx, &[], (&ml_shaders::EXPOSURE_METER_COMP, &curve))?,
            sums: (0..FRAMES_IN_FLIGHT).map(|_| Buffer::null()).collect(),
            readback: ReadBack::new("exposure meter read-back"),
            groups: vec![0; FRAMES_IN_FLIGHT],
        })
    }
}

impl Pass for ExposureMeter {
    fn timer_name(&self) -> Option<&'static str> {
        Some("exposure meter")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let extent = frame.targets.color.extent;
        // A sum per work group of the pass's dispatch.
        let (x, y) = self.pass.groups(extent);
        let groups = x * y;
        let slot = frame.slot;
        if groups != self.groups[slot] {
            // A new size (no frame of this slot in flight while it is bound).
            self.sums[slot].destroy(ctx);
            self.groups[slot] = 0;
            let bytes = groups as u64 * 8;
            let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC;
            self.sums[slot] = Buffer::new(ctx, "exposure meter sums", bytes, usage, MemoryLocation::GpuOnly)?;
            self.readback.make(ctx, slot, bytes)?;
            self.groups[slot] = groups;
        }
        let sums = Resource::Buffer(self.sums[slot].raw);
        self.pass.bind_frame_with(ctx, frame, &|name| (name == SUMS.0).then_some(sums))
    }

    /// After every pass that writes the colour target: it reads the finished image. It
    /// writes the sums after the slot's last copy of them.
    fn uses(&self) -> Vec<Use> {
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let read = (compute, vk::AccessFlags::SHADER_READ);
        vec![Use::image(COLOUR_TARGET, read, vk::ImageLayout::GENERAL), Use::buffer(SUMS, (compute, vk::AccessFlags::SHADER_WRITE))]
    }

    fn record(&self, rec: &Recording) {
        self.pass.dispatch(rec.ctx, rec.cmd, rec.slot, (&[], &[]), rec.extent);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
        for b in &mut self.sums {
            b.destroy(ctx);
        }
        self.readback.destroy(ctx);
        self.groups.fill(0);
    }

    fn frame_work(&mut self) -> Option<&mut dyn FrameWork> {
        Some(self)
    }
}

impl FrameWork for ExposureMeter {
    fn host_reads(&self, slot: usize) -> Vec<HostRead> {
        vec![self.readback.of(slot, SUMS, self.sums[slot].raw)]
    }

    fn collect(&self, slot: usize, report: &mut SlotReport, _: &mut FrameStats) {
        let bytes = self.groups[slot] as usize * 8;
        let sums: Vec<[f32; 2]> = bytemuck::pod_collect_to_vec(&self.readback.bytes(slot)[..bytes]);
        let (log2_sum, pixels) = sums.iter().fold((0.0f64, 0.0f64), |(s, n), g| (s + g[0] as f64, n + g[1] as f64));
        // A frame with no metered pixel (all background) keeps the exposure it had.
        report.log2_luminance = (pixels > 0.0).then_some((log2_sum / pixels) as f32);
    }
}
