//! One frame in flight (SPEC §6: two of them): its command buffer and fence, its own
//! persistently mapped uniform, light and cluster buffers and descriptor set (seeds 001/004),
//! its timer and its render targets. Cluster buffers grow when a frame needs more; nothing
//! is ever dropped.

use crate::cluster_build::{self as build, GpuClusterBuilder, GpuClusterFrame};
use crate::deferred::{self, ComputeLighting, LightingInputs};
use crate::raster::{
    RasterPass, BINDING_CLUSTER_RANGES, BINDING_FRAME, BINDING_LIGHTS, BINDING_LIGHT_CONES, BINDING_LIGHT_INDICES, BINDING_OBJECTS,
};
use crate::targets::Targets;
use crate::tonemap::ToneMap;
use gpu_allocator::MemoryLocation;
use ml_cpu::cluster::ClusterLists;
use ml_cpu::gpu_types::{ClusterRange, FrameUniforms, PointLight};
use ml_vk::descriptors::{allocate_set, write_buffer};
use ml_vk::{vk, Buffer, Context, GpuTimer, VkError, VkResultExt};

pub const FRAMES_IN_FLIGHT: usize = 2;

pub struct FrameInFlight {
    pub cmd: vk::CommandBuffer,
    pub fence: vk::Fence,
    pub uniforms: Buffer,
    pub lights: Buffer,
    pub cluster_ranges: Buffer,
    pub light_indices: Buffer,
    pub set: vk::DescriptorSet,
    pub timer: GpuTimer,
    pub targets: Option<Targets>,
    /// The GPU cluster build's per-frame part (clustered-gpu, deferred-compute).
    pub gpu: Option<GpuClusterFrame>,
    /// deferred-compute: the lighting pass's set (null otherwise).
    pub lighting_set: vk::DescriptorSet,
    /// deferred, deferred-clustered: set 1 of the lighting subpass and the tone map's set
    /// (null otherwise).
    pub input_set: vk::DescriptorSet,
    pub tonemap_set: vk::DescriptorSet,
    /// Where lights and cluster lists live: host-visible (written by the CPU) or device-local
    /// (written by the GPU build).
    location: MemoryLocation,
}

/// Everything `FrameInFlight::new` needs from the renderer.
pub struct FrameSetup<'a> {
    pub pool: vk::CommandPool,
    pub descriptor_pool: vk::DescriptorPool,
    pub set_layout: vk::DescriptorSetLayout,
    pub light_count: usize,
    pub cluster_count: usize,
    /// Light-index entries the list starts with (it grows on demand).
    pub initial_indices: usize,
    pub passes: u32,
    pub make_targets: &'a dyn Fn() -> Result<Targets, VkError>,
    /// Set for clustered-gpu and deferred-compute: the GPU writes lights and lists.
    pub builder: Option<&'a GpuClusterBuilder>,
    /// Set for deferred-compute: the lighting pass that reads them.
    pub lighting: Option<&'a ComputeLighting>,
    /// Set for deferred, deferred-clustered: the pass whose lighting subpass reads the
    /// G-buffer, and the tone map after it.
    pub subpasses: Option<(&'a RasterPass, &'a ToneMap)>,
    /// The object buffer (transforms and materials).
    pub objects: vk::Buffer,
    /// The lights' spot cones.
    pub cones: vk::Buffer,
}

/// Storage buffer for lights or cluster lists. Device-local ones can also be copied out
/// (tests read the GPU's lists back).
fn list_buffer(ctx: &Context, name: &str, bytes: usize, location: MemoryLocation) -> Result<Buffer, VkError> {
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC;
    Buffer::new(ctx, name, bytes as u64, usage, location)
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
            set: vk::DescriptorSet::null(),
            timer: GpuTimer::null(),
            targets: None,
            gpu: None,
            lighting_set: vk::DescriptorSet::null(),
            input_set: vk::DescriptorSet::null(),
            tonemap_set: vk::DescriptorSet::null(),
            location: if setup.builder.is_some() { MemoryLocation::GpuOnly } else { MemoryLocation::CpuToGpu },
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
        let at = self.location;
        let uniform_bytes = size_of::<FrameUniforms>() as u64;
        self.uniforms = Buffer::new(ctx, "frame uniforms", uniform_bytes, vk::BufferUsageFlags::UNIFORM_BUFFER, MemoryLocation::CpuToGpu)?;
        self.lights = list_buffer(ctx, "lights", setup.light_count * size_of::<PointLight>(), at)?;
        self.cluster_ranges = list_buffer(ctx, "cluster ranges", setup.cluster_count * size_of::<ClusterRange>(), at)?;
        self.light_indices = list_buffer(ctx, "light indices", setup.initial_indices.clamp(1, max_index_entries(ctx)) * 4, at)?;
        self.set = allocate_set(ctx, setup.descriptor_pool, setup.set_layout)?;
        self.bind(ctx, BINDING_FRAME, vk::DescriptorType::UNIFORM_BUFFER, self.uniforms.raw);
        for (binding, buffer) in [
            (BINDING_OBJECTS, setup.objects),
            (BINDING_LIGHT_CONES, setup.cones),
            (BINDING_LIGHTS, self.lights.raw),
            (BINDING_CLUSTER_RANGES, self.cluster_ranges.raw),
            (BINDING_LIGHT_INDICES, self.light_indices.raw),
        ] {
            self.bind(ctx, binding, vk::DescriptorType::STORAGE_BUFFER, buffer);
        }
        self.timer = GpuTimer::new(ctx, setup.passes)?;
        self.targets = Some((setup.make_targets)()?);
        if let Some(builder) = setup.builder {
            let gpu = builder.frame_resources(ctx, setup.descriptor_pool)?;
            let set = gpu.set;
            let (counters, feedback, blocks) = (gpu.counters.raw, gpu.feedback.raw, gpu.scan_blocks.raw);
            self.gpu = Some(gpu);
            write_buffer(ctx, set, build::BINDING_FRAME, vk::DescriptorType::UNIFORM_BUFFER, self.uniforms.raw);
            for (binding, buffer) in [
                (build::BINDING_REST_LIGHTS, builder.rest_lights.raw),
                (build::BINDING_LIGHTS, self.lights.raw),
                (build::BINDING_BOUNDS, builder.bounds.raw),
                (build::BINDING_COUNTERS, counters),
                (build::BINDING_RANGES, self.cluster_ranges.raw),
                (build::BINDING_INDICES, self.light_indices.raw),
                (build::BINDING_FEEDBACK, feedback),
                (build::BINDING_SCAN_BLOCKS, blocks),
            ] {
                write_buffer(ctx, set, binding, vk::DescriptorType::STORAGE_BUFFER, buffer);
            }
        }
        if let Some(lighting) = setup.lighting {
            let inputs = LightingInputs {
                uniforms: self.uniforms.raw,
                lights: self.lights.raw,
                ranges: self.cluster_ranges.raw,
                indices: self.light_indices.raw,
                objects: setup.objects,
                cones: setup.cones,
                targets: self.targets.as_ref().expect("made above"),
            };
            self.lighting_set = lighting.frame_set(ctx, setup.descriptor_pool, &inputs)?;
        }
        if let Some((pass, tonemap)) = setup.subpasses {
            let targets = self.targets.as_ref().expect("made above");
            self.input_set = pass.input_set(ctx, setup.descriptor_pool, targets)?;
            self.tonemap_set = tonemap.frame_set(ctx, setup.descriptor_pool, targets)?;
        }
        Ok(())
    }

    /// Point `binding` of this frame's shading set at `buffer`. Only while not in flight.
    fn bind(&self, ctx: &Context, binding: u32, ty: vk::DescriptorType, buffer: vk::Buffer) {
        write_buffer(ctx, self.set, binding, ty, buffer);
    }

    /// Entries the light-index list holds.
    pub fn index_capacity(&self) -> usize {
        (self.light_indices.size / 4) as usize
    }

    /// Grow the light-index list to hold at least `needed` entries, with room to spare (1.5×)
    /// where the device allows it; nothing if it already does. A list the device cannot bind
    /// (maxStorageBufferRange) is an error, never a silently shortened list. Returns whether
    /// it grew. Call only after the frame's fence has signalled.
    pub fn ensure_index_capacity(&mut self, ctx: &Context, needed: usize) -> Result<bool, VkError> {
        if needed <= self.index_capacity() {
            return Ok(false);
        }
        let limit = max_index_entries(ctx);
        if needed > limit {
            return Err(lists_too_long(needed, limit, &format!("'{}' binds as one storage buffer", ctx.info.name)));
        }
        let entries = (needed + needed / 2).min(limit);
        let bigger = list_buffer(ctx, "light indices", entries * 4, self.location)?;
        let mut old = std::mem::replace(&mut self.light_indices, bigger);
        old.destroy(ctx);
        let storage = vk::DescriptorType::STORAGE_BUFFER;
        self.bind(ctx, BINDING_LIGHT_INDICES, storage, self.light_indices.raw);
        if let Some(gpu) = &self.gpu {
            write_buffer(ctx, gpu.set, build::BINDING_INDICES, storage, self.light_indices.raw);
        }
        if self.lighting_set != vk::DescriptorSet::null() {
            write_buffer(ctx, self.lighting_set, deferred::BINDING_INDICES, storage, self.light_indices.raw);
        }
        Ok(true)
    }

    /// Copy the cluster lists into this frame's buffers, growing the index buffer when it is
    /// too small. Returns whether it grew. Call only after the frame's fence has signalled.
    pub fn upload_clusters(&mut self, ctx: &Context, lists: &ClusterLists) -> Result<bool, VkError> {
        let grew = self.ensure_index_capacity(ctx, lists.indices.len())?;
        self.cluster_ranges.write(0, &lists.ranges);
        self.light_indices.write(0, &lists.indices);
        Ok(grew)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        if let Some(mut gpu) = self.gpu.take() {
            gpu.destroy(ctx);
        }
        if let Some(mut t) = self.targets.take() {
            t.destroy(ctx);
        }
        self.timer.destroy(ctx);
        for b in [&mut self.uniforms, &mut self.lights, &mut self.cluster_ranges, &mut self.light_indices] {
            b.destroy(ctx);
        }
        // SAFETY: the caller waited for the device to be idle; a null fence is ignored.
        unsafe { ctx.device.destroy_fence(self.fence, None) };
        self.fence = vk::Fence::null();
    }
}

/// The most light-index entries one list may hold: what the device binds as one storage buffer.
pub fn max_index_entries(ctx: &Context) -> usize {
    ctx.info.limits.max_storage_buffer_range as usize / 4
}

/// The error for light lists longer than `limit` entries, which is what `holder` can take.
pub fn lists_too_long(needed: usize, limit: usize, holder: &str) -> VkError {
    VkError::Limit(format!(
        "the cluster light lists need at least {needed} entries ({} MiB), more than the {} MiB {holder}: use fewer or smaller lights, or a coarser --clusters grid",
        (needed as u64 * 4) >> 20,
        (limit as u64 * 4) >> 20
    ))
}

impl ml_vk::Release for FrameInFlight {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
