//! Buffers with memory from the allocator: host-visible ones stay mapped for their lifetime
//! (per-frame uniforms and lights: docs/DESIGN.md#frames-in-flight); device-local static data is
//! filled through a staging buffer that is freed right after the copy
//! (docs/DESIGN.md#conventions).

use crate::context::Context;
use crate::error::{Result, VkError, VkResultExt};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

pub struct Buffer {
    pub raw: vk::Buffer,
    pub size: vk::DeviceSize,
    allocation: Option<Allocation>,
}

impl Buffer {
    /// A buffer that owns nothing (destroying it does nothing): a placeholder while a larger
    /// object is being built.
    pub fn null() -> Buffer {
        Buffer { raw: vk::Buffer::null(), size: 0, allocation: None }
    }

    pub fn new(ctx: &Context, name: &str, size: vk::DeviceSize, usage: vk::BufferUsageFlags, location: MemoryLocation) -> Result<Buffer> {
        let info = vk::BufferCreateInfo::default().size(size.max(4)).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device and create info.
        let raw = unsafe { ctx.device.create_buffer(&info, None) }.ctx("vkCreateBuffer")?;
        // SAFETY: `raw` was just created on this device.
        let requirements = unsafe { ctx.device.get_buffer_memory_requirements(raw) };
        let allocation = ctx.allocator().allocate(&AllocationCreateDesc {
            name,
            requirements,
            location,
            linear: true,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        });
        let allocation = match allocation {
            Ok(a) => a,
            Err(source) => {
                // SAFETY: unbound, unused buffer.
                unsafe { ctx.device.destroy_buffer(raw, None) };
                return Err(VkError::Alloc { what: format!("{name} ({size} bytes)"), source });
            }
        };
        // SAFETY: memory from the allocator for exactly these requirements.
        if let Err(e) = unsafe { ctx.device.bind_buffer_memory(raw, allocation.memory(), allocation.offset()) } {
            let _ = ctx.allocator().free(allocation);
            // SAFETY: unused buffer.
            unsafe { ctx.device.destroy_buffer(raw, None) };
            return Err(VkError::Call { what: "vkBindBufferMemory", result: e });
        }
        Ok(Buffer { raw, size, allocation: Some(allocation) })
    }

    /// The mapped bytes of a host-visible buffer.
    pub fn mapped(&self) -> &[u8] {
        let slice = self.allocation.as_ref().and_then(|a| a.mapped_slice()).expect("buffer is host-visible");
        &slice[..self.size as usize]
    }

    /// Copy `data` into a host-visible buffer at byte `offset`. Host-visible memory from
    /// gpu-allocator's CpuToGpu/GpuToCpu locations is coherent, so no flush is needed; the
    /// queue submission that follows makes the writes visible to the device.
    pub fn write<T: bytemuck::Pod>(&mut self, offset: usize, data: &[T]) {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let slice = self.allocation.as_mut().and_then(|a| a.mapped_slice_mut()).expect("buffer is host-visible");
        slice[offset..offset + bytes.len()].copy_from_slice(bytes);
    }

    /// A device-local buffer filled with `data` through a staging buffer (freed after the copy).
    /// Empty data (a scene without lights) gives a minimal buffer nothing is copied into:
    /// Vulkan has no empty buffers and no empty copies.
    pub fn device_local_with(ctx: &Context, name: &str, data: &[u8], usage: vk::BufferUsageFlags) -> Result<Buffer> {
        if data.is_empty() {
            return Buffer::new(ctx, name, 0, usage, MemoryLocation::GpuOnly);
        }
        let size = data.len() as vk::DeviceSize;
        let mut staging = Buffer::new(ctx, "staging", size, vk::BufferUsageFlags::TRANSFER_SRC, MemoryLocation::CpuToGpu)?;
        staging.write(0, data);
        let result =
            Buffer::new(ctx, name, size, usage | vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuOnly).and_then(|mut buffer| {
                let copied = crate::commands::one_shot(ctx, |cmd| {
                    let region = [vk::BufferCopy::default().size(size)];
                    // SAFETY: both buffers are alive and large enough.
                    unsafe { ctx.device.cmd_copy_buffer(cmd, staging.raw, buffer.raw, &region) };
                    // Make the copy visible to every later use (vertex input, shaders).
                    crate::commands::memory_barrier(
                        ctx,
                        cmd,
                        (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE),
                        (vk::PipelineStageFlags::ALL_COMMANDS, vk::AccessFlags::MEMORY_READ),
                    );
                });
                match copied {
                    Ok(()) => Ok(buffer),
                    Err(e) => {
                        buffer.destroy(ctx);
                        Err(e)
                    }
                }
            });
        staging.destroy(ctx);
        result
    }

    pub fn destroy(&mut self, ctx: &Context) {
        if let Some(allocation) = self.allocation.take() {
            // SAFETY: the caller guarantees the GPU no longer uses the buffer.
            unsafe { ctx.device.destroy_buffer(self.raw, None) };
            let _ = ctx.allocator().free(allocation);
        }
    }
}
