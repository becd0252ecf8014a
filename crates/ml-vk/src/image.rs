//! Images (2D, arrays, cubes) with one view of the whole, memory from the allocator; their
//! layout transitions; textures uploaded through a staging buffer.

use crate::commands::one_shot;
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
    /// Memory of a transient attachment where the device has a lazily allocated kind (tilers:
    /// it may never be backed); null otherwise.
    lazy_memory: vk::DeviceMemory,
    /// Bytes of memory it takes (its requirements; 0 for a null image).
    pub bytes: u64,
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
            lazy_memory: vk::DeviceMemory::null(),
            bytes: 0,
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
        Image::new(ctx, name, ImageShape { extent, levels: 1, layers: 1, view: vk::ImageViewType::TYPE_2D }, format, usage, aspect)
    }

    /// A 2D image of `samples` samples per pixel (a multisampled attachment; `TYPE_1` makes
    /// what `new_2d` makes).
    pub fn new_2d_samples(
        ctx: &Context,
        name: &str,
        (extent, samples): (vk::Extent2D, vk::SampleCountFlags),
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        aspect: vk::ImageAspectFlags,
    ) -> Result<Image> {
        let shape = ImageShape { extent, levels: 1, layers: 1, view: vk::ImageViewType::TYPE_2D };
        Image::create(ctx, name, (shape, samples), format, usage, aspect)
    }

    /// A 2D image, 2D array, cubemap or cube-map array (`shape`) with `shape.levels` mip
    /// levels, and one view of all of it.
    pub fn new(
        ctx: &Context,
        name: &str,
        shape: ImageShape,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        aspect: vk::ImageAspectFlags,
    ) -> Result<Image> {
        Image::create(ctx, name, (shape, vk::SampleCountFlags::TYPE_1), format, usage, aspect)
    }

    fn create(
        ctx: &Context,
        name: &str,
        (shape, samples): (ImageShape, vk::SampleCountFlags),
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        aspect: vk::ImageAspectFlags,
    ) -> Result<Image> {
        let extent = shape.extent;
        let layers = shape.layers;
        let info = vk::ImageCreateInfo::default()
            .flags(if shape.is_cube() { vk::ImageCreateFlags::CUBE_COMPATIBLE } else { vk::ImageCreateFlags::empty() })
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })
            .mip_levels(shape.levels)
            .array_layers(layers)
            .samples(samples)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid device and create info.
        let raw = unsafe { ctx.device.create_image(&info, None) }.ctx("vkCreateImage")?;
        // SAFETY: `raw` was just created.
        let requirements = unsafe { ctx.device.get_image_memory_requirements(raw) };
        let mut image = Image {
            raw,
            view: vk::ImageView::null(),
            format,
            extent,
            allocation: None,
            lazy_memory: vk::DeviceMemory::null(),
            bytes: requirements.size,
        };
        let lazy_type = usage
            .contains(vk::ImageUsageFlags::TRANSIENT_ATTACHMENT)
            .then(|| ctx.lazily_allocated_memory_type(requirements.memory_type_bits))
            .flatten();
        if let Some(memory_type_index) = lazy_type {
            let info = vk::MemoryAllocateInfo::default().allocation_size(requirements.size).memory_type_index(memory_type_index);
            // SAFETY: valid device; a type the image accepts; freed in `destroy`.
            let bound = unsafe { ctx.device.allocate_memory(&info, None) }.ctx("vkAllocateMemory").and_then(|memory| {
                image.lazy_memory = memory;
                // SAFETY: fresh memory of the required size and type.
                unsafe { ctx.device.bind_image_memory(raw, memory, 0) }.ctx("vkBindImageMemory")
            });
            if let Err(e) = bound {
                image.destroy(ctx);
                return Err(e);
            }
            return image.with_view(ctx, shape, aspect);
        }
        let allocation = ctx.allocator().allocate(&AllocationCreateDesc {
            name,
            requirements,
            location: MemoryLocation::GpuOnly,
            linear: false,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        });
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
        image.with_view(ctx, shape, aspect)
    }

    /// Whether the image lives in lazily allocated memory (a transient attachment on a device
    /// that has such memory).
    pub fn is_lazily_allocated(&self) -> bool {
        self.lazy_memory != vk::DeviceMemory::null()
    }

    /// Add the view of a bound image (destroying the image if that fails).
    fn with_view(mut self, ctx: &Context, shape: ImageShape, aspect: vk::ImageAspectFlags) -> Result<Image> {
        match self.view_of(ctx, shape.view, 0..shape.layers, aspect) {
            Ok(v) => self.view = v,
            Err(e) => {
                self.destroy(ctx);
                return Err(e);
            }
        }
        Ok(self)
    }

    /// Another view of mip level 0 of `layers` (the caller destroys it before the image).
    pub fn view_of(
        &self,
        ctx: &Context,
        view_type: vk::ImageViewType,
        layers: std::ops::Range<u32>,
        aspect: vk::ImageAspectFlags,
    ) -> Result<vk::ImageView> {
        let range = vk::ImageSubresourceRange::default()
            .aspect_mask(aspect)
            .level_count(vk::REMAINING_MIP_LEVELS)
            .base_array_layer(layers.start)
            .layer_count(layers.len() as u32);
        let info = vk::ImageViewCreateInfo::default().image(self.raw).view_type(view_type).format(self.format).subresource_range(range);
        // SAFETY: bound image; the range lies within it (the caller's contract).
        unsafe { ctx.device.create_image_view(&info, None) }.ctx("vkCreateImageView")
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
        if self.lazy_memory != vk::DeviceMemory::null() {
            // SAFETY: the image bound to it was destroyed above.
            unsafe { ctx.device.free_memory(self.lazy_memory, None) };
            self.lazy_memory = vk::DeviceMemory::null();
        }
    }
}

/// Size, mip levels and kind of an image.
#[derive(Clone, Copy, Debug)]
pub struct ImageShape {
    pub extent: vk::Extent2D,
    pub levels: u32,
    /// Array layers (6 per cube).
    pub layers: u32,
    /// How `Image::view` sees all of it (a cube or cube array makes the image cube-compatible).
    pub view: vk::ImageViewType,
}

impl ImageShape {
    pub fn is_cube(&self) -> bool {
        matches!(self.view, vk::ImageViewType::CUBE | vk::ImageViewType::CUBE_ARRAY)
    }
}

/// Every mip level and layer of an image.
pub fn full_range(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default().aspect_mask(aspect).level_count(vk::REMAINING_MIP_LEVELS).layer_count(vk::REMAINING_ARRAY_LAYERS)
}

/// (stage, access, layout) on one side of a barrier.
pub type StageAccessLayout = (vk::PipelineStageFlags, vk::AccessFlags, vk::ImageLayout);

/// A colour image's layout transition: `from` (stage, access, layout) before `to`.
pub fn image_transition(ctx: &Context, cmd: vk::CommandBuffer, image: vk::Image, from: StageAccessLayout, to: StageAccessLayout) {
    aspect_transition(ctx, cmd, (image, vk::ImageAspectFlags::COLOR), from, to);
}

/// The layout transition of every mip level and layer of `aspect` of an image.
pub fn aspect_transition(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    (image, aspect): (vk::Image, vk::ImageAspectFlags),
    from: StageAccessLayout,
    to: StageAccessLayout,
) {
    let b = [vk::ImageMemoryBarrier::default()
        .src_access_mask(from.1)
        .dst_access_mask(to.1)
        .old_layout(from.2)
        .new_layout(to.2)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(full_range(aspect))];
    // SAFETY: recording state, outside a render pass.
    unsafe { ctx.device.cmd_pipeline_barrier(cmd, from.0, to.0, vk::DependencyFlags::empty(), &[], &[], &b) };
}

/// A sampled RGBA8 texture filled from `levels[level][layer]` (tightly packed texels; level
/// 0 is `shape.extent`, each next level half the size) through a staging buffer, left in
/// SHADER_READ_ONLY_OPTIMAL for fragment and compute shaders.
pub fn texture_with(ctx: &Context, name: &str, shape: ImageShape, format: vk::Format, levels: &[Vec<&[u8]>]) -> Result<Image> {
    let usage = vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST;
    let image = Image::new(ctx, name, shape, format, usage, vk::ImageAspectFlags::COLOR)?;
    let bytes: Vec<u8> = levels.iter().flatten().flat_map(|layer| layer.iter().copied()).collect();
    let staging =
        crate::Buffer::new(ctx, "texture staging", bytes.len() as u64, vk::BufferUsageFlags::TRANSFER_SRC, MemoryLocation::CpuToGpu);
    let mut staging = match staging {
        Ok(b) => b,
        Err(e) => {
            let mut image = image;
            image.destroy(ctx);
            return Err(e);
        }
    };
    staging.write(0, &bytes);
    let mut regions = Vec::new();
    let mut offset = 0u64;
    for (level, layers) in levels.iter().enumerate() {
        for (layer, data) in layers.iter().enumerate() {
            let (w, h) = ((shape.extent.width >> level).max(1), (shape.extent.height >> level).max(1));
            regions.push(
                vk::BufferImageCopy::default()
                    .buffer_offset(offset)
                    .image_subresource(
                        vk::ImageSubresourceLayers::default()
                            .aspect_mask(vk::ImageAspectFlags::COLOR)
                            .mip_level(level as u32)
                            .base_array_layer(layer as u32)
                            .layer_count(1),
                    )
                    .image_extent(vk::Extent3D { width: w, height: h, depth: 1 }),
            );
            offset += data.len() as u64;
        }
    }
    let copied = one_shot(ctx, |cmd| {
        let whole = vk::PipelineStageFlags::TRANSFER;
        let to_transfer = (whole, vk::AccessFlags::TRANSFER_WRITE, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
        image_transition(
            ctx,
            cmd,
            image.raw,
            (vk::PipelineStageFlags::TOP_OF_PIPE, vk::AccessFlags::empty(), vk::ImageLayout::UNDEFINED),
            to_transfer,
        );
        // SAFETY: recording state; buffer and image are alive and the regions lie within them.
        unsafe { ctx.device.cmd_copy_buffer_to_image(cmd, staging.raw, image.raw, vk::ImageLayout::TRANSFER_DST_OPTIMAL, &regions) };
        let readers = vk::PipelineStageFlags::FRAGMENT_SHADER | vk::PipelineStageFlags::COMPUTE_SHADER;
        image_transition(
            ctx,
            cmd,
            image.raw,
            to_transfer,
            (readers, vk::AccessFlags::SHADER_READ, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL),
        );
    });
    staging.destroy(ctx);
    match copied {
        Ok(()) => Ok(image),
        Err(e) => {
            let mut image = image;
            image.destroy(ctx);
            Err(e)
        }
    }
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

/// A sampler (clamp-to-border samples read opaque white); `compare`: a depth comparison.
pub fn sampler(ctx: &Context, address: vk::SamplerAddressMode, filter: vk::Filter, compare: Option<vk::CompareOp>) -> Result<vk::Sampler> {
    let info = vk::SamplerCreateInfo::default()
        .mag_filter(filter)
        .min_filter(filter)
        .mipmap_mode(if filter == vk::Filter::LINEAR { vk::SamplerMipmapMode::LINEAR } else { vk::SamplerMipmapMode::NEAREST })
        .address_mode_u(address)
        .address_mode_v(address)
        .address_mode_w(address)
        .border_color(vk::BorderColor::FLOAT_OPAQUE_WHITE)
        .compare_enable(compare.is_some())
        .compare_op(compare.unwrap_or(vk::CompareOp::ALWAYS))
        .max_lod(vk::LOD_CLAMP_NONE);
    // SAFETY: valid device and create info.
    unsafe { ctx.device.create_sampler(&info, None) }.ctx("vkCreateSampler")
}
