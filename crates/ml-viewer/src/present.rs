//! Putting a rendered frame on the window: the frame's colour target is blitted into the
//! acquired swapchain image, the egui overlay is drawn over it in a small render pass that
//! leaves the image ready to present — all in the frame's own command buffer (a FrameHook of
//! the renderer) — and, when asked, the presented image is copied out (window-shot).

use egui_ash_renderer::{Options, Renderer};
use ml_render::FrameHook;
use ml_vk::image::image_transition;
use ml_vk::swapchain::Swapchain;
use ml_vk::{vk, Buffer, Context, Image, MemoryLocation, VkError, VkResultExt};

pub struct Presenter {
    pub swapchain: Swapchain,
    render_pass: vk::RenderPass,
    framebuffers: Vec<vk::Framebuffer>,
    /// Per frame slot: signalled when the acquired image may be written.
    acquired: Vec<vk::Semaphore>,
    /// Per swapchain image: signalled when its frame is drawn (presentation waits on it).
    rendered: Vec<vk::Semaphore>,
    pub egui: Option<Renderer>,
    /// The last window-shot's pixels (host-visible), its size and format.
    capture: Option<(Buffer, vk::Extent2D, vk::Format)>,
}

impl Presenter {
    pub fn new(ctx: &Context, size: vk::Extent2D, vsync: bool, slots: usize) -> anyhow::Result<Presenter> {
        let swapchain = Swapchain::new(ctx, size, vsync, vk::SwapchainKHR::null())?;
        let mut p = Presenter {
            render_pass: vk::RenderPass::null(),
            framebuffers: Vec::new(),
            acquired: Vec::new(),
            rendered: Vec::new(),
            egui: None,
            capture: None,
            swapchain,
        };
        if let Err(e) = p.create(ctx, slots) {
            p.destroy(ctx);
            return Err(e);
        }
        Ok(p)
    }

    fn create(&mut self, ctx: &Context, slots: usize) -> anyhow::Result<()> {
        self.render_pass = overlay_render_pass(ctx, self.swapchain.format)?;
        for _ in 0..slots {
            self.acquired.push(semaphore(ctx)?);
        }
        self.make_framebuffers(ctx)?;
        let options = Options { in_flight_frames: slots, enable_depth_test: false, enable_depth_write: false, srgb_framebuffer: false };
        self.egui =
            Some(Renderer::with_default_allocator(ctx.instance(), ctx.physical_device, ctx.device.clone(), self.render_pass, options)?);
        Ok(())
    }

    fn make_framebuffers(&mut self, ctx: &Context) -> Result<(), VkError> {
        let extent = self.swapchain.extent;
        for &view in &self.swapchain.views {
            let views = [view];
            let info = vk::FramebufferCreateInfo::default()
                .render_pass(self.render_pass)
                .attachments(&views)
                .width(extent.width)
                .height(extent.height)
                .layers(1);
            // SAFETY: a view of this swapchain and a render pass of its format.
            self.framebuffers.push(unsafe { ctx.device.create_framebuffer(&info, None) }.ctx("vkCreateFramebuffer")?);
            self.rendered.push(semaphore(ctx)?);
        }
        Ok(())
    }

    /// Make the swapchain again for `size` (after a resize or an out-of-date report); the device
    /// must be idle.
    pub fn recreate(&mut self, ctx: &Context, size: vk::Extent2D, vsync: bool) -> anyhow::Result<()> {
        self.destroy_per_image(ctx);
        let made = Swapchain::new(ctx, size, vsync, self.swapchain.raw)?;
        // The old swapchain is retired into the new one and idle: destroy it and its views.
        let mut retired = std::mem::replace(&mut self.swapchain, made);
        retired.destroy(ctx);
        self.make_framebuffers(ctx)?;
        Ok(())
    }

    pub fn acquire_semaphore(&self, slot: usize) -> vk::Semaphore {
        self.acquired[slot]
    }

    pub fn rendered_semaphore(&self, image: u32) -> vk::Semaphore {
        self.rendered[image as usize]
    }

    /// The pixels of the last window-shot as RGBA8 rows (call after its frame finished).
    pub fn captured_rgba(&self) -> Option<(u32, u32, Vec<u8>)> {
        let (buffer, extent, format) = self.capture.as_ref()?;
        let mut rgba = buffer.mapped().to_vec();
        if *format == vk::Format::B8G8R8A8_UNORM {
            for p in rgba.chunks_exact_mut(4) {
                p.swap(0, 2);
            }
        }
        Some((extent.width, extent.height, rgba))
    }

    fn destroy_per_image(&mut self, ctx: &Context) {
        // SAFETY: the device is idle (the caller's contract).
        unsafe {
            for fb in self.framebuffers.drain(..) {
                ctx.device.destroy_framebuffer(fb, None);
            }
            for s in self.rendered.drain(..) {
                ctx.device.destroy_semaphore(s, None);
            }
        }
    }

    /// Release everything (the device must be idle).
    pub fn destroy(&mut self, ctx: &Context) {
        self.egui = None;
        self.destroy_per_image(ctx);
        if let Some((mut b, _, _)) = self.capture.take() {
            b.destroy(ctx);
        }
        // SAFETY: as above; null handles are ignored.
        unsafe {
            for s in self.acquired.drain(..) {
                ctx.device.destroy_semaphore(s, None);
            }
            ctx.device.destroy_render_pass(self.render_pass, None);
        }
        self.render_pass = vk::RenderPass::null();
        self.swapchain.destroy(ctx);
    }
}

/// One frame's additions: blit, overlay, optional capture, on swapchain image `image`.
pub struct PresentFrame<'p> {
    pub presenter: &'p mut Presenter,
    pub image: u32,
    pub slot: usize,
    pub primitives: &'p [egui::ClippedPrimitive],
    pub pixels_per_point: f32,
    pub capture: bool,
}

impl FrameHook for PresentFrame<'_> {
    fn record(&mut self, ctx: &Context, cmd: vk::CommandBuffer, colour: &Image) -> Result<(), VkError> {
        let p = &mut *self.presenter;
        let image = p.swapchain.images[self.image as usize];
        let extent = p.swapchain.extent;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let attachment_out = vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT;
        // The acquire semaphore is waited on at TRANSFER: nothing touches the image before.
        image_transition(
            ctx,
            cmd,
            image,
            (transfer, vk::AccessFlags::empty(), vk::ImageLayout::UNDEFINED),
            (transfer, vk::AccessFlags::TRANSFER_WRITE, vk::ImageLayout::TRANSFER_DST_OPTIMAL),
        );
        // The window may be larger or smaller than the rendered image for a frame while a
        // resize is under way: blit what overlaps.
        let w = extent.width.min(colour.extent.width) as i32;
        let h = extent.height.min(colour.extent.height) as i32;
        let layers = vk::ImageSubresourceLayers::default().aspect_mask(vk::ImageAspectFlags::COLOR).layer_count(1);
        let region = [vk::ImageBlit::default()
            .src_subresource(layers)
            .src_offsets([vk::Offset3D::default(), vk::Offset3D { x: w, y: h, z: 1 }])
            .dst_subresource(layers)
            .dst_offsets([vk::Offset3D::default(), vk::Offset3D { x: w, y: h, z: 1 }])];
        // SAFETY: recording state; the colour target is in TRANSFER_SRC_OPTIMAL with its writes
        // made visible to transfers by the frame's last barrier (the renderer's).
        unsafe {
            ctx.device.cmd_blit_image(
                cmd,
                colour.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &region,
                vk::Filter::NEAREST,
            )
        };
        image_transition(
            ctx,
            cmd,
            image,
            (transfer, vk::AccessFlags::TRANSFER_WRITE, vk::ImageLayout::TRANSFER_DST_OPTIMAL),
            (
                attachment_out,
                vk::AccessFlags::COLOR_ATTACHMENT_READ | vk::AccessFlags::COLOR_ATTACHMENT_WRITE,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            ),
        );
        let begin = vk::RenderPassBeginInfo::default()
            .render_pass(p.render_pass)
            .framebuffer(p.framebuffers[self.image as usize])
            .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent });
        // SAFETY: recording state; render pass and framebuffer match.
        unsafe { ctx.device.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE) };
        if let Some(egui) = &mut p.egui {
            egui.cmd_draw(cmd, extent, self.pixels_per_point, self.primitives)
                .map_err(|e| VkError::Library { name: "the overlay's renderer (egui-ash)", message: e.to_string() })?;
        }
        // SAFETY: inside the render pass begun above.
        unsafe { ctx.device.cmd_end_render_pass(cmd) };
        if self.capture {
            capture(ctx, cmd, p, image)?;
        }
        Ok(())
    }

    fn semaphores(&self) -> (Option<(vk::Semaphore, vk::PipelineStageFlags)>, Option<vk::Semaphore>) {
        let p = &*self.presenter;
        (Some((p.acquired[self.slot], vk::PipelineStageFlags::TRANSFER)), Some(p.rendered[self.image as usize]))
    }
}

/// Copy swapchain image `image` (PRESENT_SRC_KHR, after the overlay pass) to the capture buffer.
fn capture(ctx: &Context, cmd: vk::CommandBuffer, p: &mut Presenter, image: vk::Image) -> Result<(), VkError> {
    let extent = p.swapchain.extent;
    let bytes = extent.width as u64 * extent.height as u64 * 4;
    if p.capture.as_ref().is_none_or(|(b, e, _)| b.size != bytes || *e != extent) {
        if let Some((mut old, _, _)) = p.capture.take() {
            old.destroy(ctx);
        }
        let buffer = Buffer::new(ctx, "window shot", bytes, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)?;
        p.capture = Some((buffer, extent, p.swapchain.format));
    }
    let (buffer, _, _) = p.capture.as_ref().expect("made above");
    let transfer = vk::PipelineStageFlags::TRANSFER;
    // The overlay pass's exit dependency made its writes visible to transfers.
    image_transition(
        ctx,
        cmd,
        image,
        (transfer, vk::AccessFlags::empty(), vk::ImageLayout::PRESENT_SRC_KHR),
        (transfer, vk::AccessFlags::TRANSFER_READ, vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
    );
    ml_vk::commands::copy_colour_to_host(ctx, cmd, image, extent, buffer.raw);
    image_transition(
        ctx,
        cmd,
        image,
        (transfer, vk::AccessFlags::TRANSFER_READ, vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
        (vk::PipelineStageFlags::BOTTOM_OF_PIPE, vk::AccessFlags::empty(), vk::ImageLayout::PRESENT_SRC_KHR),
    );
    Ok(())
}

fn semaphore(ctx: &Context) -> Result<vk::Semaphore, VkError> {
    // SAFETY: valid device and create info.
    unsafe { ctx.device.create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }.ctx("vkCreateSemaphore")
}

/// The overlay's pass: loads what the blit wrote, draws egui, leaves the image for presenting
/// (or a window-shot's copy).
fn overlay_render_pass(ctx: &Context, format: vk::Format) -> Result<vk::RenderPass, VkError> {
    let attachments = [vk::AttachmentDescription::default()
        .format(format)
        .samples(vk::SampleCountFlags::TYPE_1)
        .load_op(vk::AttachmentLoadOp::LOAD)
        .store_op(vk::AttachmentStoreOp::STORE)
        .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
        .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
        .initial_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
        .final_layout(vk::ImageLayout::PRESENT_SRC_KHR)];
    let colour = [vk::AttachmentReference { attachment: 0, layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL }];
    let subpasses = [vk::SubpassDescription::default().pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS).color_attachments(&colour)];
    let out = vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT;
    let rw = vk::AccessFlags::COLOR_ATTACHMENT_READ | vk::AccessFlags::COLOR_ATTACHMENT_WRITE;
    let dependencies = [
        // The blit's layout change (a barrier before the pass) to the overlay's blending.
        vk::SubpassDependency::default()
            .src_subpass(vk::SUBPASS_EXTERNAL)
            .dst_subpass(0)
            .src_stage_mask(out)
            .src_access_mask(rw)
            .dst_stage_mask(out)
            .dst_access_mask(rw),
        // The overlay before presentation or a window-shot's copy.
        vk::SubpassDependency::default()
            .src_subpass(0)
            .dst_subpass(vk::SUBPASS_EXTERNAL)
            .src_stage_mask(out)
            .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags::TRANSFER)
            .dst_access_mask(vk::AccessFlags::TRANSFER_READ),
    ];
    let info = vk::RenderPassCreateInfo::default().attachments(&attachments).subpasses(&subpasses).dependencies(&dependencies);
    // SAFETY: valid device and create info.
    unsafe { ctx.device.create_render_pass(&info, None) }.ctx("vkCreateRenderPass")
}
