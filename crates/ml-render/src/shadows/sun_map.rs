//! The sun's shadow map's render pass, shared by the store that makes and clears the map
//! (stores.rs) and the pass that draws it (sun_shadow.rs).

use crate::depth_pass::{self, DepthPassDesc};
use ml_vk::{vk, Context, Image, VkError, VkResultExt};

/// Who reads the map once it is drawn.
pub(crate) const READERS: vk::PipelineStageFlags =
    vk::PipelineStageFlags::from_raw(vk::PipelineStageFlags::FRAGMENT_SHADER.as_raw() | vk::PipelineStageFlags::COMPUTE_SHADER.as_raw());

/// Clear `target` to the far plane ("lit everywhere") and leave it
/// DEPTH_STENCIL_READ_ONLY_OPTIMAL: the map before its casters are drawn, and the stand-in
/// where none is drawn.
pub(crate) fn clear_shadow_map(ctx: &Context, target: &Image) -> Result<(), VkError> {
    let render_pass = map_render_pass(ctx, target.format, vk::PipelineStageFlags::empty())?;
    let framebuffer = framebuffer(ctx, render_pass, target)?;
    let cleared = ml_vk::commands::one_shot(ctx, |cmd| {
        // SAFETY: recording state; the render pass and framebuffer live until one_shot's wait.
        unsafe {
            ctx.device.cmd_begin_render_pass(cmd, &begin_info(render_pass, framebuffer, target.extent), vk::SubpassContents::INLINE);
            ctx.device.cmd_end_render_pass(cmd);
        }
    });
    // SAFETY: one_shot waited for the GPU (or nothing was submitted).
    unsafe { ctx.device.destroy_framebuffer(framebuffer, None) };
    cleared
}

/// The map's depth-only render pass: cleared, drawn, left DEPTH_STENCIL_READ_ONLY_OPTIMAL for
/// the shaders; after `after` (the shaders that read it last).
pub(crate) fn map_render_pass(ctx: &Context, format: vk::Format, after: vk::PipelineStageFlags) -> Result<vk::RenderPass, VkError> {
    depth_pass::render_pass(
        ctx,
        &DepthPassDesc {
            format,
            final_layout: vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL,
            after,
            readers: (READERS, vk::AccessFlags::SHADER_READ),
            view_mask: 0,
        },
    )
}

pub(crate) fn framebuffer(ctx: &Context, render_pass: vk::RenderPass, target: &Image) -> Result<vk::Framebuffer, VkError> {
    let views = [target.view];
    let info = vk::FramebufferCreateInfo::default()
        .render_pass(render_pass)
        .attachments(&views)
        .width(target.extent.width)
        .height(target.extent.height)
        .layers(1);
    // SAFETY: valid device and create info; the view outlives the framebuffer (its owner
    // destroys it first).
    unsafe { ctx.device.create_framebuffer(&info, None) }.ctx("vkCreateFramebuffer")
}

pub(crate) fn begin_info(
    render_pass: vk::RenderPass,
    framebuffer: vk::Framebuffer,
    extent: vk::Extent2D,
) -> vk::RenderPassBeginInfo<'static> {
    vk::RenderPassBeginInfo::default()
        .render_pass(render_pass)
        .framebuffer(framebuffer)
        .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent })
        .clear_values(&depth_pass::CLEAR_FAR)
}
