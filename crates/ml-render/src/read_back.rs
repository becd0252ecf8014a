//! What the host reads of a frame once its slot's fence has signalled (statistics, the
//! exposure meter's sums), declared by the passes (`FrameWork::host_reads`) and carried out by the
//! renderer at the frame's end: one barrier the sync model derives from every declared read
//! orders each buffer after its last use in the frame, then the copies of the buffers that
//! live in device memory, then one barrier that makes the copies visible to the host. No pass
//! orders or records a read-back of its own; the next frame of the slot that writes such a
//! buffer again is ordered after the copy by the same model (the read is the buffer's last
//! use).

use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::sync::{BufferName, Use};
use gpu_allocator::MemoryLocation;
use ml_vk::commands::transfer_to_host_barrier;
use ml_vk::{vk, Buffer, Context, VkError};

/// One buffer of the frame the host reads after it: in place (the shaders wrote it in
/// host-visible memory) or copied into a slot's `ReadBack`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HostRead {
    /// The buffer's name in the frame (its shader block's).
    pub name: BufferName,
    /// (device buffer, host buffer, bytes) where the frame's end copies it.
    copy: Option<(vk::Buffer, vk::Buffer, vk::DeviceSize)>,
}

impl HostRead {
    /// The host reads the host-visible buffer `name` where the shaders wrote it.
    pub fn in_place(name: BufferName) -> HostRead {
        HostRead { name, copy: None }
    }

    /// The buffer's last use in the frame: a transfer's read where it is copied, else the
    /// host's.
    pub fn at_frame_end(&self) -> Use {
        let end = match self.copy {
            Some(_) => (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_READ),
            None => (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ),
        };
        Use::buffer(self.name, end)
    }
}

/// Record the copies among `reads` and make them visible to the host (after the barrier of
/// their `at_frame_end` uses).
pub fn record_copies(ctx: &Context, cmd: vk::CommandBuffer, reads: &[HostRead]) {
    let copies: Vec<_> = reads.iter().filter_map(|r| r.copy).collect();
    for &(from, to, bytes) in &copies {
        // SAFETY: recording state outside a render pass; both buffers live until the frame's
        // fence signals, and the barrier before made the writes visible to transfers.
        unsafe { ctx.device.cmd_copy_buffer(cmd, from, to, &[vk::BufferCopy::default().size(bytes)]) };
    }
    if !copies.is_empty() {
        transfer_to_host_barrier(ctx, cmd);
    }
}

/// The host-visible copies of one device buffer (or image), a buffer per frame slot.
pub struct ReadBack {
    label: &'static str,
    host: Vec<Buffer>,
}

impl ReadBack {
    /// No buffer yet (`make` one per slot); `label` names them for tools and errors.
    pub fn new(label: &'static str) -> ReadBack {
        ReadBack { label, host: (0..FRAMES_IN_FLIGHT).map(|_| Buffer::null()).collect() }
    }

    /// Slot `slot`'s copy, `bytes` long, replacing the one it had (no frame of the slot in
    /// flight); zeros until a frame of the slot has copied into it, so that a reader before
    /// the first frame (a list growing by what the last frame asked for) reads nothing asked.
    pub fn make(&mut self, ctx: &Context, slot: usize, bytes: vk::DeviceSize) -> Result<(), VkError> {
        self.host[slot].destroy(ctx);
        self.host[slot] = Buffer::new(ctx, self.label, bytes, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)?;
        self.host[slot].write(0, &vec![0u8; bytes as usize]);
        Ok(())
    }

    /// `make` for every slot.
    pub fn make_all(&mut self, ctx: &Context, bytes: vk::DeviceSize) -> Result<(), VkError> {
        (0..FRAMES_IN_FLIGHT).try_for_each(|slot| self.make(ctx, slot, bytes))
    }

    /// The read of `name` (the device buffer `from`) into slot `slot`'s copy, as long as it.
    pub fn of(&self, slot: usize, name: BufferName, from: vk::Buffer) -> HostRead {
        let host = &self.host[slot];
        HostRead { name, copy: Some((from, host.raw, host.size)) }
    }

    /// Slot `slot`'s host buffer (for a copy recorded elsewhere: the colour target's).
    pub fn raw(&self, slot: usize) -> vk::Buffer {
        self.host[slot].raw
    }

    /// Slot `slot`'s copy as its finished frame left it.
    pub fn bytes(&self, slot: usize) -> &[u8] {
        self.host[slot].mapped()
    }

    /// The copy's first bytes as a `T`.
    pub fn read<T: bytemuck::Pod>(&self, slot: usize) -> T {
        bytemuck::pod_read_unaligned(&self.bytes(slot)[..size_of::<T>()])
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for b in &mut self.host {
            b.destroy(ctx);
        }
    }
}
