//! One frame in flight (SPEC §6: two of them): its command buffer and fence, its own
//! persistently mapped uniform and light buffers and descriptor set (seeds 001/004), its
//! timer and its render targets.

use crate::forward::{BINDING_FRAME, BINDING_LIGHTS};
use crate::targets::Targets;
use ml_cpu::gpu_types::{FrameUniforms, PointLight};
use ml_vk::{vk, Buffer, Context, GpuTimer, VkError, VkResultExt};

pub const FRAMES_IN_FLIGHT: usize = 2;

pub struct FrameInFlight {
    pub cmd: vk::CommandBuffer,
    pub fence: vk::Fence,
    pub uniforms: Buffer,
    pub lights: Buffer,
    pub set: vk::DescriptorSet,
    pub timer: GpuTimer,
    pub targets: Targets,
}

/// Everything `FrameInFlight::new` needs from the renderer.
pub struct FrameSetup<'a> {
    pub pool: vk::CommandPool,
    pub descriptor_pool: vk::DescriptorPool,
    pub set_layout: vk::DescriptorSetLayout,
    pub light_count: usize,
    pub make_targets: &'a dyn Fn() -> Result<Targets, VkError>,
}

impl FrameInFlight {
    /// Builds into `out` piece by piece so that a failure leaves only objects that
    /// `destroy_partial` can release.
    pub fn new(ctx: &Context, setup: &FrameSetup) -> Result<FrameInFlight, VkError> {
        let d = &ctx.device;
        let alloc = vk::CommandBufferAllocateInfo::default().command_pool(setup.pool).command_buffer_count(1);
        // SAFETY: valid pool; everything below uses valid create infos on this device.
        let cmd = unsafe { d.allocate_command_buffers(&alloc) }.ctx("vkAllocateCommandBuffers")?[0];
        let fence = unsafe { d.create_fence(&vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED), None) }
            .ctx("vkCreateFence")?;
        let mut uniforms = Buffer::new(
            ctx,
            "frame uniforms",
            std::mem::size_of::<FrameUniforms>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            gpu_allocator::MemoryLocation::CpuToGpu,
        )
        .inspect_err(|_| unsafe { d.destroy_fence(fence, None) })?;
        let light_bytes = (setup.light_count * std::mem::size_of::<PointLight>()) as u64;
        let mut lights = Buffer::new(ctx, "lights", light_bytes, vk::BufferUsageFlags::STORAGE_BUFFER, gpu_allocator::MemoryLocation::CpuToGpu)
            .inspect_err(|_| {
                uniforms.destroy(ctx);
                unsafe { d.destroy_fence(fence, None) }
            })?;
        let cleanup = |uniforms: &mut Buffer, lights: &mut Buffer| {
            uniforms.destroy(ctx);
            lights.destroy(ctx);
            // SAFETY: never submitted.
            unsafe { d.destroy_fence(fence, None) };
        };
        let layouts = [setup.set_layout];
        let set_info = vk::DescriptorSetAllocateInfo::default().descriptor_pool(setup.descriptor_pool).set_layouts(&layouts);
        let set = match unsafe { d.allocate_descriptor_sets(&set_info) }.ctx("vkAllocateDescriptorSets") {
            Ok(s) => s[0],
            Err(e) => {
                cleanup(&mut uniforms, &mut lights);
                return Err(e);
            }
        };
        let ubo = [vk::DescriptorBufferInfo::default().buffer(uniforms.raw).range(vk::WHOLE_SIZE)];
        let ssbo = [vk::DescriptorBufferInfo::default().buffer(lights.raw).range(vk::WHOLE_SIZE)];
        let writes = [
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(BINDING_FRAME)
                .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER)
                .buffer_info(&ubo),
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(BINDING_LIGHTS)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .buffer_info(&ssbo),
        ];
        // SAFETY: the set and buffers are alive and unused.
        unsafe { d.update_descriptor_sets(&writes, &[]) };
        let mut timer = match GpuTimer::new(ctx, 1) {
            Ok(t) => t,
            Err(e) => {
                cleanup(&mut uniforms, &mut lights);
                return Err(e);
            }
        };
        let targets = match (setup.make_targets)() {
            Ok(t) => t,
            Err(e) => {
                timer.destroy(ctx);
                cleanup(&mut uniforms, &mut lights);
                return Err(e);
            }
        };
        Ok(FrameInFlight { cmd, fence, uniforms, lights, set, timer, targets })
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.targets.destroy(ctx);
        self.timer.destroy(ctx);
        self.uniforms.destroy(ctx);
        self.lights.destroy(ctx);
        // SAFETY: the caller waited for the device to be idle.
        unsafe { ctx.device.destroy_fence(self.fence, None) };
    }
}
