//! The window's swapchain (the viewer): made for the surface's current size, made again when
//! the window changes size or the surface reports it out of date.

use crate::error::{Result, VkError, VkResultExt};
use crate::Context;
use ash::vk;

pub struct Swapchain {
    loader: ash::khr::swapchain::Device,
    pub raw: vk::SwapchainKHR,
    pub images: Vec<vk::Image>,
    pub views: Vec<vk::ImageView>,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    pub present_mode: vk::PresentModeKHR,
}

/// What acquiring an image gave.
pub enum Acquired {
    /// Image `index`; `suboptimal`: it can be presented, but the swapchain should be remade.
    Image { index: u32, suboptimal: bool },
    /// The swapchain no longer fits the surface: make it again before drawing.
    OutOfDate,
}

impl Swapchain {
    /// A swapchain for the context's surface at `size` (clamped to what the surface allows):
    /// FIFO with `vsync`, else mailbox or immediate where the surface has them. Images are
    /// 8-bit UNORM (the renderer writes gamma-encoded values itself) and can be blitted to,
    /// drawn to and copied from (screenshots). `old` is retired into the new one.
    pub fn new(ctx: &Context, size: vk::Extent2D, vsync: bool, old: vk::SwapchainKHR) -> Result<Swapchain> {
        let surface = ctx.surface().ok_or(VkError::NoSurface)?;
        let pd = ctx.physical_device;
        // SAFETY: queries on our physical device and surface.
        let (caps, formats, modes) = unsafe {
            (
                surface
                    .loader
                    .get_physical_device_surface_capabilities(pd, surface.raw)
                    .ctx("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?,
                surface.loader.get_physical_device_surface_formats(pd, surface.raw).ctx("vkGetPhysicalDeviceSurfaceFormatsKHR")?,
                surface
                    .loader
                    .get_physical_device_surface_present_modes(pd, surface.raw)
                    .ctx("vkGetPhysicalDeviceSurfacePresentModesKHR")?,
            )
        };
        let format =
            formats.iter().find(|f| matches!(f.format, vk::Format::B8G8R8A8_UNORM | vk::Format::R8G8B8A8_UNORM)).copied().ok_or_else(
                || VkError::Unsupported {
                    device: ctx.info.name.clone(),
                    what: format!("a window surface format of 8-bit UNORM colour (it offers {formats:?})"),
                },
            )?;
        let present_mode = if vsync {
            vk::PresentModeKHR::FIFO
        } else {
            [vk::PresentModeKHR::MAILBOX, vk::PresentModeKHR::IMMEDIATE]
                .into_iter()
                .find(|m| modes.contains(m))
                .unwrap_or(vk::PresentModeKHR::FIFO)
        };
        // A current extent of u32::MAX means "the size of the swapchain decides".
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: size.width.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: size.height.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::TRANSFER_SRC;
        if !caps.supported_usage_flags.contains(usage) {
            return Err(VkError::Unsupported {
                device: ctx.info.name.clone(),
                what: format!("window surface images with {usage:?} (they have {:?})", caps.supported_usage_flags),
            });
        }
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(surface.raw)
            .min_image_count(count)
            .image_format(format.format)
            .image_color_space(format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(present_mode)
            .clipped(true)
            .old_swapchain(old);
        let loader = ash::khr::swapchain::Device::new(ctx.instance(), &ctx.device);
        // SAFETY: valid device, surface and create info.
        let raw = unsafe { loader.create_swapchain(&info, None) }.ctx("vkCreateSwapchainKHR")?;
        let mut chain = Swapchain { loader, raw, images: Vec::new(), views: Vec::new(), format: format.format, extent, present_mode };
        // SAFETY: a swapchain of this device.
        match unsafe { chain.loader.get_swapchain_images(raw) }.ctx("vkGetSwapchainImagesKHR") {
            Ok(images) => chain.images = images,
            Err(e) => {
                chain.destroy(ctx);
                return Err(e);
            }
        }
        for &image in &chain.images.clone() {
            let view = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(chain.format)
                .subresource_range(
                    vk::ImageSubresourceRange::default().aspect_mask(vk::ImageAspectFlags::COLOR).level_count(1).layer_count(1),
                );
            // SAFETY: an image of this swapchain.
            match unsafe { ctx.device.create_image_view(&view, None) }.ctx("vkCreateImageView") {
                Ok(v) => chain.views.push(v),
                Err(e) => {
                    chain.destroy(ctx);
                    return Err(e);
                }
            }
        }
        Ok(chain)
    }

    /// The next image to draw into; `signal` is signalled when it may be written.
    pub fn acquire(&self, signal: vk::Semaphore) -> Result<Acquired> {
        // SAFETY: our swapchain; the semaphore is unsignalled with no pending signal (the caller's).
        match unsafe { self.loader.acquire_next_image(self.raw, u64::MAX, signal, vk::Fence::null()) } {
            Ok((index, suboptimal)) => Ok(Acquired::Image { index, suboptimal }),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(Acquired::OutOfDate),
            Err(e) => Err(VkError::Call { what: "vkAcquireNextImageKHR", result: e }),
        }
    }

    /// Present image `index` once `wait` is signalled; false if the swapchain should be made
    /// again (out of date or suboptimal).
    pub fn present(&self, ctx: &Context, index: u32, wait: vk::Semaphore) -> Result<bool> {
        let (chains, indices, waits) = ([self.raw], [index], [wait]);
        let info = vk::PresentInfoKHR::default().wait_semaphores(&waits).swapchains(&chains).image_indices(&indices);
        // SAFETY: our queue and swapchain; the image was acquired and is in PRESENT_SRC_KHR.
        match unsafe { self.loader.queue_present(ctx.queue, &info) } {
            Ok(suboptimal) => Ok(!suboptimal),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(false),
            Err(e) => Err(VkError::Call { what: "vkQueuePresentKHR", result: e }),
        }
    }

    /// Destroy views and swapchain (the device must be done with them).
    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: no pending work uses them (the caller's contract); null handles are ignored.
        unsafe {
            for view in self.views.drain(..) {
                ctx.device.destroy_image_view(view, None);
            }
            self.loader.destroy_swapchain(self.raw, None);
        }
        self.raw = vk::SwapchainKHR::null();
        self.images.clear();
    }
}
