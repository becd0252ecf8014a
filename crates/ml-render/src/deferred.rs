//! Technique `deferred-compute`: the raster pass writes a G-buffer (raster.rs, Output::GBuffer)
//! and this compute pass lights it through the clustered-gpu lists — the same BRDF, cluster
//! lookup and light order as the fragment path, on every SM (H100/H200 give graphics work 4 of
//! 132). Its output is the colour target, left in TRANSFER_SRC_OPTIMAL like the forward pass's.

use crate::compute_pass::ComputePass;
use crate::settings::Shading;
use crate::targets::Targets;
use ml_vk::descriptors::{allocate_set, write_buffer, write_image};
use ml_vk::{vk, Context, VkError};

/// Bindings of the lighting set (deferred_lighting.comp).
pub const BINDING_FRAME: u32 = 0;
pub const BINDING_LIGHTS: u32 = 1;
pub const BINDING_RANGES: u32 = 2;
pub const BINDING_INDICES: u32 = 3;
pub const BINDING_OBJECTS: u32 = 4;
pub const BINDING_DEPTH: u32 = 5;
pub const BINDING_NORMAL: u32 = 6;
pub const BINDING_OBJECT_ID: u32 = 7;
pub const BINDING_OUTPUT: u32 = 8;
pub const BINDING_ALBEDO: u32 = 9;
pub const BINDING_LIGHT_CONES: u32 = 10;
pub const BINDING_ROUGHNESS_METALLIC: u32 = 11;
pub const BINDING_EMISSIVE: u32 = 12;
/// Where each of GBUFFER's images is bound.
const GBUFFER_BINDINGS: [u32; crate::targets::GBUFFER.len()] =
    [BINDING_NORMAL, BINDING_OBJECT_ID, BINDING_ALBEDO, BINDING_ROUGHNESS_METALLIC, BINDING_EMISSIVE];

pub struct ComputeLighting {
    pass: ComputePass,
}

/// Descriptors of one frame's lighting set.
pub struct LightingInputs<'a> {
    pub uniforms: vk::Buffer,
    pub lights: vk::Buffer,
    pub ranges: vk::Buffer,
    pub indices: vk::Buffer,
    /// Every object's material (what the raster pass pushes), indexed by the G-buffer.
    pub objects: vk::Buffer,
    /// The lights' spot cones.
    pub cones: vk::Buffer,
    pub targets: &'a Targets,
}

impl ComputeLighting {
    pub fn new(ctx: &Context, textures_layout: vk::DescriptorSetLayout, shading: Shading) -> Result<ComputeLighting, VkError> {
        use vk::DescriptorType as T;
        let storage = T::STORAGE_BUFFER;
        let image = T::COMBINED_IMAGE_SAMPLER;
        let bindings = [
            (BINDING_FRAME, T::UNIFORM_BUFFER),
            (BINDING_LIGHTS, storage),
            (BINDING_RANGES, storage),
            (BINDING_INDICES, storage),
            (BINDING_OBJECTS, storage),
            (BINDING_LIGHT_CONES, storage),
            (BINDING_DEPTH, image),
            (BINDING_NORMAL, image),
            (BINDING_OBJECT_ID, image),
            (BINDING_OUTPUT, T::STORAGE_IMAGE),
            (BINDING_ALBEDO, image),
            (BINDING_ROUGHNESS_METALLIC, image),
            (BINDING_EMISSIVE, image),
        ];
        // Set 1: the scene's textures (blinn-phong's shadow map and sky).
        let model = shading.spec_constants();
        let pass = ComputePass::new(ctx, &bindings, &[textures_layout], (ml_shaders::DEFERRED_LIGHTING_COMP, &model))?;
        Ok(ComputeLighting { pass })
    }

    /// Allocate and fill a frame's lighting set.
    pub fn frame_set(&self, ctx: &Context, pool: vk::DescriptorPool, inputs: &LightingInputs) -> Result<vk::DescriptorSet, VkError> {
        let set = allocate_set(ctx, pool, self.pass.set_layout)?;
        write_buffer(ctx, set, BINDING_FRAME, vk::DescriptorType::UNIFORM_BUFFER, inputs.uniforms);
        for (binding, buffer) in [
            (BINDING_LIGHTS, inputs.lights),
            (BINDING_RANGES, inputs.ranges),
            (BINDING_INDICES, inputs.indices),
            (BINDING_OBJECTS, inputs.objects),
            (BINDING_LIGHT_CONES, inputs.cones),
        ] {
            write_buffer(ctx, set, binding, vk::DescriptorType::STORAGE_BUFFER, buffer);
        }
        let t = inputs.targets;
        let sampled = |view: vk::ImageView, layout: vk::ImageLayout| {
            vk::DescriptorImageInfo::default().sampler(self.pass.sampler).image_view(view).image_layout(layout)
        };
        let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let image = vk::DescriptorType::COMBINED_IMAGE_SAMPLER;
        write_image(ctx, set, BINDING_DEPTH, image, sampled(t.depth.view, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL));
        // A G-buffer without the material and emissive images (a scene without object
        // textures) binds the albedo image in their place: the shader, specialised for such
        // scenes, never reads them, but Vulkan wants every binding it names written.
        for (i, binding) in GBUFFER_BINDINGS.into_iter().enumerate() {
            let g = t.gbuffer.get(i).unwrap_or(&t.gbuffer[2]);
            write_image(ctx, set, binding, image, sampled(g.view, read_only));
        }
        let output = vk::DescriptorImageInfo::default().image_view(t.color.view).image_layout(vk::ImageLayout::GENERAL);
        write_image(ctx, set, BINDING_OUTPUT, vk::DescriptorType::STORAGE_IMAGE, output);
        Ok(set)
    }

    /// Record the lighting of `targets` (after the raster pass and the cluster build).
    pub fn record(&self, ctx: &Context, cmd: vk::CommandBuffer, sets: [vk::DescriptorSet; 2], targets: &Targets, extent: vk::Extent2D) {
        self.pass.record_into_colour_target(ctx, cmd, &sets, targets.color.raw, extent);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
    }
}
