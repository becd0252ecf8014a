//! Descriptor sets: allocate one, point a binding at a whole buffer or at an image.

use crate::context::Context;
use crate::error::{Result, VkResultExt};
use ash::vk;

/// One set of `layout` from `pool`.
pub fn allocate_set(ctx: &Context, pool: vk::DescriptorPool, layout: vk::DescriptorSetLayout) -> Result<vk::DescriptorSet> {
    let layouts = [layout];
    let info = vk::DescriptorSetAllocateInfo::default().descriptor_pool(pool).set_layouts(&layouts);
    // SAFETY: valid pool and layout; a full pool is reported as an error.
    Ok(unsafe { ctx.device.allocate_descriptor_sets(&info) }.ctx("vkAllocateDescriptorSets")?[0])
}

/// Point `binding` of `set` at the whole of `buffer`. Only while the set is not in use.
pub fn write_buffer(ctx: &Context, set: vk::DescriptorSet, binding: u32, ty: vk::DescriptorType, buffer: vk::Buffer) {
    let info = [vk::DescriptorBufferInfo::default().buffer(buffer).range(vk::WHOLE_SIZE)];
    let write = [vk::WriteDescriptorSet::default().dst_set(set).dst_binding(binding).descriptor_type(ty).buffer_info(&info)];
    // SAFETY: the set and buffer are alive and the set is not in use by pending work.
    unsafe { ctx.device.update_descriptor_sets(&write, &[]) };
}

/// Point `binding` of `set` at an image (view, layout and, for sampled kinds, the sampler in
/// `image`). Only while the set is not in use.
pub fn write_image(ctx: &Context, set: vk::DescriptorSet, binding: u32, ty: vk::DescriptorType, image: vk::DescriptorImageInfo) {
    let info = [image];
    let write = [vk::WriteDescriptorSet::default().dst_set(set).dst_binding(binding).descriptor_type(ty).image_info(&info)];
    // SAFETY: the set and the image view (and sampler) are alive and the set is not in use.
    unsafe { ctx.device.update_descriptor_sets(&write, &[]) };
}
