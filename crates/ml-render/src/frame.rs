//! One frame in flight (two of them: docs/DESIGN.md#frames-in-flight): its command buffer and
//! fence, its own persistently mapped buffer of per-frame values (FrameUniforms), the light
//! and cluster-list buffers the CPU writes (a placeholder each where the light grid keeps the
//! lights), its timer and its render targets. The passes point their own per-frame sets at these. Cluster buffers grow
//! when a frame needs more; nothing is ever dropped.

use crate::error::{ListsTooLong, RenderError};
use crate::frame_resources::FrameResources;
use crate::pass::ListUpload;
use crate::sync::{BufferName, SyncStates, FRAME_BLOCK, LIGHT_LISTS, RAY_COUNT};
use crate::targets::Targets;
use gpu_allocator::MemoryLocation;
use ml_cpu::cluster::ClusterLists;
use ml_cpu::gpu_types::{ClusterRange, FrameUniforms, PointLight};
use ml_vk::image::fetch_sampler;
use ml_vk::{vk, Buffer, Context, GpuTimer, VkError, VkResultExt};

pub struct FrameInFlight {
    pub cmd: vk::CommandBuffer,
    pub fence: vk::Fence,
    pub uniforms: Buffer,
    pub lights: Buffer,
    pub cluster_ranges: Buffer,
    pub light_indices: Buffer,
    /// The shadow rays the compute lightings traced (host-visible; zeroed before each frame).
    pub ray_count: Buffer,
    pub timer: GpuTimer,
    pub targets: Option<Targets>,
    /// Its named resources' states between passes, from frame to frame (`sync`).
    pub sync: SyncStates,
    /// How its passes' shaders read the targets they sample.
    fetch: vk::Sampler,
}

/// Everything `FrameInFlight::new` needs from the renderer.
pub struct FrameSetup<'a> {
    pub pool: vk::CommandPool,
    pub light_count: usize,
    pub cluster_count: usize,
    /// Light-index entries the list starts with (it grows on demand).
    pub initial_indices: usize,
    pub passes: u32,
    pub make_targets: &'a dyn Fn() -> Result<Targets, VkError>,
}

/// Storage buffer for lights or cluster lists, written by the CPU.
fn list_buffer(ctx: &Context, name: &str, bytes: usize) -> Result<Buffer, VkError> {
    Buffer::new(ctx, name, bytes as u64, vk::BufferUsageFlags::STORAGE_BUFFER, MemoryLocation::CpuToGpu)
}

impl FrameInFlight {
    pub fn new(ctx: &Context, setup: &FrameSetup) -> Result<FrameInFlight, VkError> {
        let frame = FrameInFlight {
            cmd: vk::CommandBuffer::null(),
            fence: vk::Fence::null(),
            uniforms: Buffer::null(),
            lights: Buffer::null(),
            cluster_ranges: Buffer::null(),
            light_indices: Buffer::null(),
            ray_count: Buffer::null(),
            timer: GpuTimer::null(),
            targets: None,
            sync: SyncStates::default(),
            fetch: vk::Sampler::null(),
        };
        // On failure everything made so far is released (null parts are skipped).
        ml_vk::build(ctx, frame, |f| f.create(ctx, setup))
    }

    fn create(&mut self, ctx: &Context, setup: &FrameSetup) -> Result<(), VkError> {
        let d = &ctx.device;
        let alloc = vk::CommandBufferAllocateInfo::default().command_pool(setup.pool).command_buffer_count(1);
        // SAFETY: valid pool and create infos on this device.
        self.cmd = unsafe { d.allocate_command_buffers(&alloc) }.ctx("vkAllocateCommandBuffers")?[0];
        // SAFETY: as above.
        self.fence =
            unsafe { d.create_fence(&vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED), None) }.ctx("vkCreateFence")?;
        let uniform_bytes = size_of::<FrameUniforms>() as u64;
        self.uniforms = Buffer::new(ctx, "frame uniforms", uniform_bytes, vk::BufferUsageFlags::STORAGE_BUFFER, MemoryLocation::CpuToGpu)?;
        self.lights = list_buffer(ctx, "lights", setup.light_count * size_of::<PointLight>())?;
        self.cluster_ranges = list_buffer(ctx, "cluster ranges", setup.cluster_count * size_of::<ClusterRange>())?;
        self.light_indices = list_buffer(ctx, "light indices", setup.initial_indices.clamp(1, max_index_entries(ctx)) * 4)?;
        self.ray_count = Buffer::new(ctx, "ray count", 16, vk::BufferUsageFlags::STORAGE_BUFFER, MemoryLocation::GpuToCpu)?;
        self.ray_count.write(0, &[0u32; 4]);
        self.timer = GpuTimer::new(ctx, setup.passes)?;
        self.targets = Some((setup.make_targets)()?);
        self.fetch = fetch_sampler(ctx)?;
        Ok(())
    }

    /// What slot `slot`'s passes bind: this frame's buffers and targets under their shader
    /// names, with the scene's `scene` added.
    pub fn resources(&self, slot: usize, scene: &[(BufferName, vk::Buffer)]) -> FrameResources<'_> {
        let targets = self.targets.as_ref().expect("made with the frame");
        FrameResources::new(slot, targets, self.fetch)
            .with(&[
                (FRAME_BLOCK, self.uniforms.raw),
                (LIGHT_LISTS[0], self.lights.raw),
                (LIGHT_LISTS[1], self.cluster_ranges.raw),
                (LIGHT_LISTS[2], self.light_indices.raw),
                (RAY_COUNT, self.ray_count.raw),
            ])
            .with(scene)
    }

    /// The shadow rays the slot's last frame traced from its opaque surfaces (compute lightings
    /// with rays; 0 elsewhere) and the surfaces it shaded (anti-aliased visibility lighting; 0
    /// elsewhere), and zero for the next: call only after its fence has signalled.
    pub fn take_ray_count(&mut self) -> (u64, u64) {
        let [traced, surfaces] = bytemuck::pod_read_unaligned::<[u32; 2]>(&self.ray_count.mapped()[..8]);
        self.ray_count.write(0, &[0u32; 4]);
        (u64::from(traced), u64::from(surfaces))
    }

    /// Entries the light-index list holds.
    pub fn index_capacity(&self) -> usize {
        (self.light_indices.size / 4) as usize
    }

    /// Grow the light-index list to hold at least `needed` entries, with room to spare (1.5×)
    /// where the device allows it; nothing if it already does. A list the device cannot bind
    /// (maxStorageBufferRange) is an error, never a silently shortened list. Returns whether
    /// it grew (the passes must then be bound to it again). Call only after the frame's fence
    /// has signalled.
    pub fn ensure_index_capacity(&mut self, ctx: &Context, needed: usize) -> Result<bool, RenderError> {
        if needed <= self.index_capacity() {
            return Ok(false);
        }
        let limit = max_index_entries(ctx);
        if needed > limit {
            return Err(lists_too_long(needed, limit, &format!("'{}' binds as one storage buffer", ctx.info.name)));
        }
        let entries = (needed + needed / 2).min(limit);
        let bigger = list_buffer(ctx, "light indices", entries * 4)?;
        let mut old = std::mem::replace(&mut self.light_indices, bigger);
        old.destroy(ctx);
        Ok(true)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        if let Some(mut t) = self.targets.take() {
            t.destroy(ctx);
        }
        self.timer.destroy(ctx);
        for b in [&mut self.uniforms, &mut self.lights, &mut self.cluster_ranges, &mut self.light_indices, &mut self.ray_count] {
            b.destroy(ctx);
        }
        // SAFETY: the caller waited for the device to be idle; null handles are ignored.
        unsafe {
            ctx.device.destroy_fence(self.fence, None);
            ctx.device.destroy_sampler(self.fetch, None);
        }
        self.fence = vk::Fence::null();
        self.fetch = vk::Sampler::null();
    }
}

/// The most light-index entries one list may hold: what the device binds as one storage buffer.
pub fn max_index_entries(ctx: &Context) -> usize {
    ctx.info.limits.max_storage_buffer_range as usize / 4
}

/// The error for light lists longer than `limit` entries, which is what `holder` can take.
pub fn lists_too_long(needed: usize, limit: usize, holder: &str) -> RenderError {
    RenderError::ListsTooLong(ListsTooLong { needed, limit, holder: holder.into(), technique: None })
}

impl ml_vk::Release for FrameInFlight {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}

/// A CPU assignment's lists into a frame slot's buffers, noting whether the index list grew.
pub struct SlotLists<'a> {
    pub frame: &'a mut FrameInFlight,
    pub grew: bool,
}

impl ListUpload for SlotLists<'_> {
    /// Copy the lists into the slot's buffers, growing the index buffer when it is too small.
    fn upload(&mut self, ctx: &Context, lists: &ClusterLists) -> Result<(), RenderError> {
        self.grew |= self.frame.ensure_index_capacity(ctx, lists.indices.len())?;
        self.frame.cluster_ranges.write(0, &lists.ranges);
        self.frame.light_indices.write(0, &lists.indices);
        Ok(())
    }

    fn max_entries(&self, ctx: &Context) -> usize {
        max_index_entries(ctx)
    }
}
