//! The renderer under a window: the seed scene drawn every frame and presented through the
//! renderer's frame hook. The hook's commands blit the finished image into the acquired
//! swapchain image, in the frame's own command buffer; its semaphores make the submission wait
//! for the acquire and signal the present.
//! `cargo run --release -p ml-render --example window [FRAMES]` (no count: until closed;
//! `ML_VALIDATION=1` turns the validation layers on).

use ml_cpu::lights::LightParams;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::Scene;
use ml_render::report::FrameStats;
use ml_render::{Exposure, FrameHook, RenderSettings, Renderer, Technique, FRAMES_IN_FLIGHT};
use ml_vk::image::image_transition;
use ml_vk::swapchain::{Acquired, Swapchain};
use ml_vk::{vk, Context, ContextDesc, Image, VkError, VkResultExt, WindowHandles};
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::platform::pump_events::{EventLoopExtPumpEvents, PumpStatus};
use winit::window::{Window, WindowId};

/// The window and what happened to it since the last frame.
#[derive(Default)]
struct Events {
    window: Option<Window>,
    closed: bool,
    resized: bool,
}

impl ApplicationHandler for Events {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_none() {
            let attributes = Window::default_attributes().with_title("manylights").with_inner_size(winit::dpi::PhysicalSize::new(960, 540));
            self.window = event_loop.create_window(attributes).ok();
            self.closed |= self.window.is_none();
        }
    }

    fn window_event(&mut self, _: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => self.closed = true,
            WindowEvent::Resized(_) => self.resized = true,
            _ => {}
        }
    }
}

/// The frame hook: the finished colour target (TRANSFER_SRC_OPTIMAL, its writes visible to
/// transfers) blitted into swapchain image `image`, left ready to present.
struct Blit<'a> {
    swapchain: &'a Swapchain,
    image: u32,
    acquired: vk::Semaphore,
    rendered: vk::Semaphore,
}

impl FrameHook for Blit<'_> {
    fn record(&mut self, ctx: &Context, cmd: vk::CommandBuffer, colour: &Image) -> Result<(), VkError> {
        let (image, extent) = (self.swapchain.images[self.image as usize], self.swapchain.extent);
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let write = (transfer, vk::AccessFlags::TRANSFER_WRITE, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
        // The submission waits for the acquire at TRANSFER: nothing touches the image before.
        image_transition(ctx, cmd, image, (transfer, vk::AccessFlags::empty(), vk::ImageLayout::UNDEFINED), write);
        // What overlaps, while a resize is under way.
        let (w, h) = (extent.width.min(colour.extent.width) as i32, extent.height.min(colour.extent.height) as i32);
        let layers = vk::ImageSubresourceLayers::default().aspect_mask(vk::ImageAspectFlags::COLOR).layer_count(1);
        let corners = [vk::Offset3D::default(), vk::Offset3D { x: w, y: h, z: 1 }];
        let region = [vk::ImageBlit::default().src_subresource(layers).src_offsets(corners).dst_subresource(layers).dst_offsets(corners)];
        let (src, dst) = (vk::ImageLayout::TRANSFER_SRC_OPTIMAL, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
        // SAFETY: recording state outside a render pass; both images are alive and in these layouts.
        unsafe { ctx.device.cmd_blit_image(cmd, colour.raw, src, image, dst, &region, vk::Filter::NEAREST) };
        // The present waits on the submission's semaphore: no later stage to make it visible to.
        let present = (vk::PipelineStageFlags::BOTTOM_OF_PIPE, vk::AccessFlags::empty(), vk::ImageLayout::PRESENT_SRC_KHR);
        image_transition(ctx, cmd, image, write, present);
        Ok(())
    }

    fn semaphores(&self) -> (Option<(vk::Semaphore, vk::PipelineStageFlags)>, Option<vk::Semaphore>) {
        (Some((self.acquired, vk::PipelineStageFlags::TRANSFER)), Some(self.rendered))
    }
}

fn semaphore(ctx: &Context) -> Result<vk::Semaphore, VkError> {
    // SAFETY: valid device and create info.
    unsafe { ctx.device.create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }.ctx("vkCreateSemaphore")
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let frames: Option<u64> = std::env::args().nth(1).map(|n| n.parse()).transpose()?;
    let mut event_loop = EventLoop::new()?;
    let mut events = Events::default();
    while events.window.is_none() && !events.closed {
        event_loop.pump_app_events(Some(Duration::from_millis(10)), &mut events);
    }
    let window = events.window.take().ok_or("cannot open a window (no display? run under xvfb-run)")?;
    let handles = WindowHandles { display: window.display_handle()?.as_raw(), window: window.window_handle()?.as_raw() };
    let validation = std::env::var_os("ML_VALIDATION").is_some();
    let ctx = Context::new(&ContextDesc { validation, device_index: None, window: Some(handles) })?;
    let size = window.inner_size();
    let mut swapchain = Swapchain::new(&ctx, vk::Extent2D { width: size.width, height: size.height }, true, vk::SwapchainKHR::null())?;
    // The seed's teapot and its 64 lights, the GPU-built clusters, exposure metered each frame.
    let scene = Scene::seed(MeshKind::Teapot, Material::named("gold")?, &LightParams::seed_default())?;
    let (width, height) = (swapchain.extent.width, swapchain.extent.height);
    let settings = RenderSettings { exposure: Exposure::Auto, frames: 1, ..RenderSettings::new(Technique::ClusteredGpu, width, height) };
    let mut renderer = Renderer::new(&ctx, scene, settings)?;
    let acquired = (0..FRAMES_IN_FLIGHT).map(|_| semaphore(&ctx)).collect::<Result<Vec<_>, _>>()?;
    let mut rendered = swapchain.images.iter().map(|_| semaphore(&ctx)).collect::<Result<Vec<_>, _>>()?;
    let start = Instant::now();
    let mut drawn = 0;
    while frames.is_none_or(|n| drawn < n) {
        if let PumpStatus::Exit(_) = event_loop.pump_app_events(Some(Duration::ZERO), &mut events) {
            break;
        }
        if events.closed {
            break;
        }
        if std::mem::take(&mut events.resized) {
            // New swapchain images (a semaphore each: their count may change), new frame slots
            // at the new size.
            ctx.wait_idle()?;
            let size = window.inner_size();
            let fresh = Swapchain::new(&ctx, vk::Extent2D { width: size.width.max(1), height: size.height.max(1) }, true, swapchain.raw)?;
            std::mem::replace(&mut swapchain, fresh).destroy(&ctx);
            while rendered.len() < swapchain.images.len() {
                rendered.push(semaphore(&ctx)?);
            }
            let (width, height) = (swapchain.extent.width, swapchain.extent.height);
            renderer.reconfigure(RenderSettings { width, height, ..*renderer.settings() })?;
        }
        let mut stats = FrameStats::new(&renderer.timed_passes());
        let slot = renderer.wait_next_slot(&mut stats)?;
        let image = match swapchain.acquire(acquired[slot])? {
            Acquired::Image { index, .. } => index,
            Acquired::OutOfDate => {
                events.resized = true;
                continue;
            }
        };
        let mut blit = Blit { swapchain: &swapchain, image, acquired: acquired[slot], rendered: rendered[image as usize] };
        renderer.draw(start.elapsed().as_secs_f32(), &mut blit, &mut stats)?;
        events.resized |= !swapchain.present(&ctx, image, rendered[image as usize])?;
        drawn += 1;
    }
    ctx.wait_idle()?;
    println!("{drawn} frames in {:.1} s", start.elapsed().as_secs_f64());
    drop(renderer);
    // SAFETY: the device is idle; nothing uses the semaphores.
    unsafe {
        for s in acquired.into_iter().chain(rendered) {
            ctx.device.destroy_semaphore(s, None);
        }
    }
    swapchain.destroy(&ctx);
    Ok(())
}
