//! After the deferred render pass: the HDR image (linear RGBA16F) → the 8-bit colour target
//! that is read back, with the encoding the forward path applies in its fragment shader
//! (tonemap.comp). A compute pass: on H100/H200 it runs on every SM.

use crate::compute_pass::ComputePass;
use crate::settings::SPEC_PBR;
use crate::targets::Targets;
use ml_vk::descriptors::{allocate_set, write_image};
use ml_vk::{vk, Context, VkError};

const BINDING_HDR: u32 = 0;
const BINDING_OUTPUT: u32 = 1;

pub struct ToneMap {
    pass: ComputePass,
}

impl ToneMap {
    /// `aces`: apply pbr's tone-mapping curve before gamma (not for debug views, whose
    /// values are shown as they are).
    pub fn new(ctx: &Context, aces: bool) -> Result<ToneMap, VkError> {
        use vk::DescriptorType as T;
        let bindings = [(BINDING_HDR, T::COMBINED_IMAGE_SAMPLER), (BINDING_OUTPUT, T::STORAGE_IMAGE)];
        let curve = [(SPEC_PBR, u32::from(aces))];
        Ok(ToneMap { pass: ComputePass::new(ctx, &bindings, &[], (ml_shaders::TONEMAP_COMP, &curve))? })
    }

    /// Allocate and fill a frame's set: its HDR image in, its colour target out.
    pub fn frame_set(&self, ctx: &Context, pool: vk::DescriptorPool, targets: &Targets) -> Result<vk::DescriptorSet, VkError> {
        let set = allocate_set(ctx, pool, self.pass.set_layout)?;
        let hdr = vk::DescriptorImageInfo::default()
            .sampler(self.pass.sampler)
            .image_view(targets.hdr.view)
            .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        write_image(ctx, set, BINDING_HDR, vk::DescriptorType::COMBINED_IMAGE_SAMPLER, hdr);
        let out = vk::DescriptorImageInfo::default().image_view(targets.color.view).image_layout(vk::ImageLayout::GENERAL);
        write_image(ctx, set, BINDING_OUTPUT, vk::DescriptorType::STORAGE_IMAGE, out);
        Ok(set)
    }

    /// Record the tone map of `targets` (after the render pass, whose outgoing dependency
    /// orders the HDR writes before this pass's reads).
    pub fn record(&self, ctx: &Context, cmd: vk::CommandBuffer, set: vk::DescriptorSet, targets: &Targets, extent: vk::Extent2D) {
        self.pass.record_into_colour_target(ctx, cmd, &[set], targets.color.raw, extent);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
    }
}
