//! 2D images with one view, memory from the allocator.

use crate::context::Context;
use crate::error::{Result, VkError, VkResultExt};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

pub struct Image {
    pub raw: vk::Image,
    pub view: vk::ImageView,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    allocation: Option<Allocation>,
}

impl Image {
    /// An image that owns nothing (destroying it does nothing): a placeholder while a larger
    /// object is being built.
    pub fn null() -> Image {
        Image {
            raw: vk::Image::null(),
            view: vk::ImageView::null(),
            format: vk::Format::UNDEFINED,
            extent: vk::Extent2D::default(),
            allocation: None,
        }
    }

    pub fn new_2d(
        ctx: &Context,
        name: &str,
        extent: vk::Extent2D,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        aspect: vk::ImageAspectFlags,
    ) -> Result<Image> {
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid device and create info.
        let raw = unsafe { ctx.device.create_image(&info, None) }.ctx("vkCreateImage")?;
        // SAFETY: `raw` was just created.
        let requirements = unsafe { ctx.device.get_image_memory_requirements(raw) };
        let allocation = ctx.allocator().allocate(&AllocationCreateDesc {
            name,
            requirements,
            location: MemoryLocation::GpuOnly,
            linear: false,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        });
        let mut image = Image { raw, view: vk::ImageView::null(), format, extent, allocation: None };
        match allocation {
            Ok(a) => image.allocation = Some(a),
            Err(source) => {
                image.destroy(ctx);
                return Err(VkError::Alloc { what: format!("{name} ({}×{})", extent.width, extent.height), source });
            }
        }
        let a = image.allocation.as_ref().expect("set above");
        // SAFETY: memory from the allocator for these requirements.
        if let Err(e) = unsafe { ctx.device.bind_image_memory(raw, a.memory(), a.offset()) }.ctx("vkBindImageMemory") {
            image.destroy(ctx);
            return Err(e);
        }
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(full_range(aspect));
        // SAFETY: bound image.
        match unsafe { ctx.device.create_image_view(&view_info, None) }.ctx("vkCreateImageView") {
            Ok(v) => image.view = v,
            Err(e) => {
                image.destroy(ctx);
                return Err(e);
            }
        }
        Ok(image)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the caller guarantees the GPU no longer uses the image.
        unsafe {
            if self.view != vk::ImageView::null() {
                ctx.device.destroy_image_view(self.view, None);
                self.view = vk::ImageView::null();
            }
            if self.raw != vk::Image::null() {
                ctx.device.destroy_image(self.raw, None);
                self.raw = vk::Image::null();
            }
        }
        if let Some(a) = self.allocation.take() {
            let _ = ctx.allocator().free(a);
        }
    }
}

pub fn full_range(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default().aspect_mask(aspect).level_count(1).layer_count(1)
}

/// A sampler for `texelFetch`-only images: it ignores filtering, but a combined image sampler
/// needs one.
pub fn fetch_sampler(ctx: &Context) -> Result<vk::Sampler> {
    let info = vk::SamplerCreateInfo::default()
        .mag_filter(vk::Filter::NEAREST)
        .min_filter(vk::Filter::NEAREST)
        .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE);
    // SAFETY: valid device and create info.
    unsafe { ctx.device.create_sampler(&info, None) }.ctx("vkCreateSampler")
}
