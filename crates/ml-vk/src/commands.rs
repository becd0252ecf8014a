//! One-shot command buffers for setup work (uploads, read-backs), waited on with a fence, and
//! the memory barriers they record.

use crate::context::Context;
use crate::error::{Result, VkResultExt};
use ash::vk;

/// Record `record` into a fresh command buffer, submit it and wait until the GPU is done.
pub fn one_shot(ctx: &Context, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
    let alloc = vk::CommandBufferAllocateInfo::default()
        .command_pool(ctx.transient_pool)
        .level(vk::CommandBufferLevel::PRIMARY)
        .command_buffer_count(1);
    // SAFETY: valid pool on this device.
    let cmd = unsafe { ctx.device.allocate_command_buffers(&alloc) }.ctx("vkAllocateCommandBuffers")?[0];
    // SAFETY: valid device.
    let fence = match unsafe { ctx.device.create_fence(&vk::FenceCreateInfo::default(), None) }.ctx("vkCreateFence") {
        Ok(f) => f,
        Err(e) => {
            // SAFETY: never submitted.
            unsafe { ctx.device.free_command_buffers(ctx.transient_pool, &[cmd]) };
            return Err(e);
        }
    };
    let result = (|| {
        let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: fresh command buffer.
        unsafe { ctx.device.begin_command_buffer(cmd, &begin) }.ctx("vkBeginCommandBuffer")?;
        record(cmd);
        // SAFETY: recording state.
        unsafe { ctx.device.end_command_buffer(cmd) }.ctx("vkEndCommandBuffer")?;
        let cmds = [cmd];
        let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
        // SAFETY: executable command buffer; the fence is unsignalled.
        unsafe { ctx.device.queue_submit(ctx.queue, &submit, fence) }.ctx("vkQueueSubmit")?;
        // SAFETY: the fence belongs to this device.
        unsafe { ctx.device.wait_for_fences(&[fence], true, u64::MAX) }.ctx("vkWaitForFences")
    })();
    // SAFETY: on success the GPU is done with both; on failure wait for whatever was submitted.
    unsafe {
        if result.is_err() {
            let _ = ctx.device.device_wait_idle();
        }
        ctx.device.destroy_fence(fence, None);
        ctx.device.free_command_buffers(ctx.transient_pool, &[cmd]);
    }
    result
}

/// A global memory barrier: `src` (stages, accesses) before `dst` (stages, accesses).
pub fn memory_barrier(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    src: (vk::PipelineStageFlags, vk::AccessFlags),
    dst: (vk::PipelineStageFlags, vk::AccessFlags),
) {
    let b = [vk::MemoryBarrier::default().src_access_mask(src.1).dst_access_mask(dst.1)];
    // SAFETY: recording state, outside a render pass.
    unsafe { ctx.device.cmd_pipeline_barrier(cmd, src.0, dst.0, vk::DependencyFlags::empty(), &b, &[], &[]) };
}

/// The most bytes one vkCmdUpdateBuffer writes.
const UPDATE_LIMIT: usize = 65536;

/// Write `bytes` (a multiple of 4) into `buffer` from offset 0 in the command stream
/// (vkCmdUpdateBuffer, in pieces of at most 64 KiB), so that each frame in flight sees its
/// own; the caller makes the transfer writes visible to their readers.
pub fn update_buffer(ctx: &Context, cmd: vk::CommandBuffer, buffer: vk::Buffer, bytes: &[u8]) {
    for (i, chunk) in bytes.chunks(UPDATE_LIMIT).enumerate() {
        // SAFETY: recording state outside a render pass; the caller's buffer is alive, holds
        // `bytes` and allows transfer writes.
        unsafe { ctx.device.cmd_update_buffer(cmd, buffer, (i * UPDATE_LIMIT) as u64, chunk) };
    }
}

/// Make every copy recorded so far visible to the host (read-backs).
pub fn transfer_to_host_barrier(ctx: &Context, cmd: vk::CommandBuffer) {
    memory_barrier(
        ctx,
        cmd,
        (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE),
        (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ),
    );
}

/// Copy a colour image's first level (`extent`, in TRANSFER_SRC_OPTIMAL, its writes already
/// made visible to transfers) into `buffer`, tightly packed, and make the copy visible to the
/// host (read-backs and screenshots).
pub fn copy_colour_to_host(ctx: &Context, cmd: vk::CommandBuffer, image: vk::Image, extent: vk::Extent2D, buffer: vk::Buffer) {
    let region = [vk::BufferImageCopy::default()
        .image_subresource(vk::ImageSubresourceLayers::default().aspect_mask(vk::ImageAspectFlags::COLOR).layer_count(1))
        .image_extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })];
    // SAFETY: recording state; the caller's image and buffer are alive and large enough.
    unsafe { ctx.device.cmd_copy_image_to_buffer(cmd, image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, buffer, &region) };
    transfer_to_host_barrier(ctx, cmd);
}
