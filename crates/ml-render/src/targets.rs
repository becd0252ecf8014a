//! Offscreen render targets (colour + depth + framebuffer) for headless rendering.

use ml_vk::{vk, Context, Image, VkError, VkResultExt};

/// Colour target format: the seed writes gamma-encoded values itself, so plain UNORM.
pub const COLOR_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

/// The first depth format the device can render to (one of these two is guaranteed).
pub fn depth_format(ctx: &Context) -> Result<vk::Format, VkError> {
    [vk::Format::D32_SFLOAT, vk::Format::X8_D24_UNORM_PACK32]
        .into_iter()
        .find(|&f| ctx.format_supports(f, vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT))
        .ok_or_else(|| VkError::Unsupported { device: ctx.info.name.clone(), what: "a depth attachment format".into() })
}

pub struct Targets {
    pub color: Image,
    pub depth: Image,
    pub framebuffer: vk::Framebuffer,
}

impl Targets {
    pub fn new(ctx: &Context, render_pass: vk::RenderPass, extent: vk::Extent2D, depth_format: vk::Format) -> Result<Targets, VkError> {
        let mut color = Image::new_2d(
            ctx,
            "colour target",
            extent,
            COLOR_FORMAT,
            vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
            vk::ImageAspectFlags::COLOR,
        )?;
        let mut depth = match Image::new_2d(
            ctx,
            "depth target",
            extent,
            depth_format,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
            vk::ImageAspectFlags::DEPTH,
        ) {
            Ok(d) => d,
            Err(e) => {
                color.destroy(ctx);
                return Err(e);
            }
        };
        let views = [color.view, depth.view];
        let info = vk::FramebufferCreateInfo::default()
            .render_pass(render_pass)
            .attachments(&views)
            .width(extent.width)
            .height(extent.height)
            .layers(1);
        // SAFETY: views and render pass are compatible and alive.
        match unsafe { ctx.device.create_framebuffer(&info, None) }.ctx("vkCreateFramebuffer") {
            Ok(framebuffer) => Ok(Targets { color, depth, framebuffer }),
            Err(e) => {
                color.destroy(ctx);
                depth.destroy(ctx);
                Err(e)
            }
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: no pending work uses the framebuffer.
        unsafe { ctx.device.destroy_framebuffer(self.framebuffer, None) };
        self.color.destroy(ctx);
        self.depth.destroy(ctx);
    }
}
