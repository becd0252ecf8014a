//! Depth-only render passes and pipelines: the sun's shadow map (scene_textures.rs) and the
//! point-light shadow cubes (omni_shadow.rs). One depth attachment, cleared to 1.0 (the far
//! plane: nothing there) and stored.
//!
//! Alpha-masked objects (glTF MASK, BLEND as a mask) cast shadows of their shape through a
//! pipeline of their own (`MaskedPipeline`, shaders/shadows/shadow_mask.glsl), made only where
//! a scene has such objects; every other object keeps the depth-only pipeline.

use crate::descriptors::{FrameSets, Resource};
use crate::gpu_mesh::{vertex_attributes, vertex_binding};
use glam::Mat4;
use ml_shaders::Shader;
use ml_vk::{shader, vk, Context, VkError};

pub struct DepthPassDesc {
    pub format: vk::Format,
    /// Layout the attachment is left in.
    pub final_layout: vk::ImageLayout,
    /// Stages of earlier work on the image that the clear must wait for (write after read);
    /// empty: none.
    pub after: vk::PipelineStageFlags,
    /// Who reads the depths once the pass ends: stages and accesses.
    pub readers: (vk::PipelineStageFlags, vk::AccessFlags),
    /// Multiview: the views one draw renders into (bit i: layer i); 0: no multiview.
    pub view_mask: u32,
}

const TESTS: vk::PipelineStageFlags = vk::PipelineStageFlags::from_raw(
    vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS.as_raw() | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS.as_raw(),
);

pub fn render_pass(ctx: &Context, desc: &DepthPassDesc) -> Result<vk::RenderPass, VkError> {
    let attachment = [vk::AttachmentDescription::default()
        .format(desc.format)
        .samples(vk::SampleCountFlags::TYPE_1)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::STORE)
        .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
        .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
        .initial_layout(vk::ImageLayout::UNDEFINED)
        .final_layout(desc.final_layout)];
    let depth_ref = vk::AttachmentReference { attachment: 0, layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL };
    let subpass =
        [vk::SubpassDescription::default().pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS).depth_stencil_attachment(&depth_ref)];
    let mut dependencies = vec![vk::SubpassDependency::default()
        .src_subpass(0)
        .dst_subpass(vk::SUBPASS_EXTERNAL)
        .src_stage_mask(TESTS)
        .src_access_mask(vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE)
        .dst_stage_mask(desc.readers.0)
        .dst_access_mask(desc.readers.1)];
    if !desc.after.is_empty() {
        dependencies.push(
            vk::SubpassDependency::default()
                .src_subpass(vk::SUBPASS_EXTERNAL)
                .dst_subpass(0)
                .src_stage_mask(desc.after)
                .dst_stage_mask(TESTS)
                .dst_access_mask(vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE),
        );
    }
    let view_masks = [desc.view_mask];
    let mut multiview = vk::RenderPassMultiviewCreateInfo::default().view_masks(&view_masks).correlation_masks(&view_masks);
    let mut info = vk::RenderPassCreateInfo::default().attachments(&attachment).subpasses(&subpass).dependencies(&dependencies);
    if desc.view_mask != 0 {
        info = info.push_next(&mut multiview);
    }
    ml_vk::shader::render_pass(ctx, &info)
}

/// Depth-only pipeline: positions only, both faces (a shadow caster need not be closed),
/// depth test LESS; `fragment` None writes the rasterised depth.
pub fn pipeline(
    ctx: &Context,
    render_pass: vk::RenderPass,
    layout: vk::PipelineLayout,
    (vertex, fragment): (&[u8], Option<&[u8]>),
) -> Result<vk::Pipeline, VkError> {
    depth_pipeline(ctx, (render_pass, layout), (vertex, fragment), &vertex_attributes()[..1])
}

/// `pipeline` with the vertex attributes `attributes`.
fn depth_pipeline(
    ctx: &Context,
    (render_pass, layout): (vk::RenderPass, vk::PipelineLayout),
    (vertex, fragment): (&[u8], Option<&[u8]>),
    attributes: &[vk::VertexInputAttributeDescription],
) -> Result<vk::Pipeline, VkError> {
    let bindings = [vertex_binding()];
    shader::graphics_pipeline(
        ctx,
        &shader::GraphicsPipelineDesc {
            vertex,
            vertex_constants: &[],
            fragment,
            fragment_constants: &[],
            vertex_input: vk::PipelineVertexInputStateCreateInfo::default()
                .vertex_binding_descriptions(&bindings)
                .vertex_attribute_descriptions(attributes),
            rasterization: vk::PipelineRasterizationStateCreateInfo::default()
                .polygon_mode(vk::PolygonMode::FILL)
                .cull_mode(vk::CullModeFlags::NONE)
                .line_width(1.0),
            depth_stencil: vk::PipelineDepthStencilStateCreateInfo::default()
                .depth_test_enable(true)
                .depth_write_enable(true)
                .depth_compare_op(vk::CompareOp::LESS),
            colour_attachments: 0,
            samples: vk::SampleCountFlags::TYPE_1,
            layout,
            render_pass,
            subpass: 0,
        },
    )
}

/// Viewport and scissor covering a `size`² target.
pub fn set_square_viewport(ctx: &Context, cmd: vk::CommandBuffer, size: u32) {
    let extent = vk::Extent2D { width: size, height: size };
    let viewport = vk::Viewport { x: 0.0, y: 0.0, width: size as f32, height: size as f32, min_depth: 0.0, max_depth: 1.0 };
    // SAFETY: recording state; the bound pipeline has dynamic viewport and scissor.
    unsafe {
        ctx.device.cmd_set_viewport(cmd, 0, &[viewport]);
        ctx.device.cmd_set_scissor(cmd, 0, &[vk::Rect2D { offset: vk::Offset2D::default(), extent }]);
    }
}

/// The clear value: the far plane.
pub const CLEAR_FAR: [vk::ClearValue; 1] = [vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } }];

/// Push constants of the masked pipelines (shadow_mask.glsl `ShadowMaskPush`; keep in sync):
/// the pass's view-projection, the object's (affine) model matrix as its three rows, and the
/// object's index in the object buffer — 128 bytes, the least a device guarantees.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ShadowMaskPush {
    pub view_proj: [[f32; 4]; 4],
    pub model_rows: [[f32; 4]; 3],
    /// x: the object's index in the object buffer.
    pub object: [u32; 4],
}

impl ml_cpu::gpu_types::GpuLayout for ShadowMaskPush {
    const GLSL_NAME: &'static str = "ShadowMaskPush";
    fn field_offsets() -> Vec<(&'static str, usize)> {
        use std::mem::offset_of;
        vec![
            ("view_proj", offset_of!(ShadowMaskPush, view_proj)),
            ("model_rows", offset_of!(ShadowMaskPush, model_rows)),
            ("object", offset_of!(ShadowMaskPush, object)),
        ]
    }
}

impl ShadowMaskPush {
    /// Object `object` drawn through `model` (affine: its last row is dropped) and `view_proj`.
    pub fn new(view_proj: Mat4, model: Mat4, object: u32) -> ShadowMaskPush {
        let rows = model.transpose();
        ShadowMaskPush {
            view_proj: view_proj.to_cols_array_2d(),
            model_rows: [rows.x_axis.to_array(), rows.y_axis.to_array(), rows.z_axis.to_array()],
            object: [object, 0, 0, 0],
        }
    }
}

/// The masked objects' pipeline of a depth pass: `pipeline`'s state, with the texture
/// coordinates as a second vertex attribute and a fragment shader that discards what the
/// object's alpha mask cuts out (shadow_mask.glsl); its set 0 (the object buffer and the alpha
/// masks) once per frame slot.
pub struct MaskedPipeline {
    pub sets: FrameSets,
    pub layout: vk::PipelineLayout,
    pub pipeline: vk::Pipeline,
}

const MASK_STAGES: vk::ShaderStageFlags =
    vk::ShaderStageFlags::from_raw(vk::ShaderStageFlags::VERTEX.as_raw() | vk::ShaderStageFlags::FRAGMENT.as_raw());

impl MaskedPipeline {
    /// The pipeline of `vertex` and `fragment` (masked variants) in subpass 0 of `render_pass`,
    /// with `slots` sets.
    pub fn new(
        ctx: &Context,
        render_pass: vk::RenderPass,
        (vertex, fragment): (&Shader, &Shader),
        slots: usize,
    ) -> Result<MaskedPipeline, VkError> {
        let empty = MaskedPipeline { sets: FrameSets::empty(), layout: vk::PipelineLayout::null(), pipeline: vk::Pipeline::null() };
        ml_vk::build(ctx, empty, |m| {
            let stages = [(vertex, vk::ShaderStageFlags::VERTEX), (fragment, vk::ShaderStageFlags::FRAGMENT)];
            m.sets = FrameSets::new(ctx, &stages, 0, slots)?;
            let push = [vk::PushConstantRange::default().stage_flags(MASK_STAGES).size(size_of::<ShadowMaskPush>() as u32)];
            m.layout = shader::pipeline_layout(ctx, &[m.sets.layout.raw], &push)?;
            // Position and texture coordinates.
            let all = vertex_attributes();
            let attributes = [all[0], all[2]];
            m.pipeline = depth_pipeline(ctx, (render_pass, m.layout), (vertex.spirv, Some(fragment.spirv)), &attributes)?;
            Ok(())
        })
    }

    /// Point slot `slot`'s set at the scene's object buffer and alpha masks (only while no
    /// submitted work that uses the set is pending).
    pub fn bind(&self, ctx: &Context, slot: usize, (objects, alpha_masks): (vk::Buffer, vk::Buffer)) -> Result<(), VkError> {
        self.sets.write(ctx, slot, &|name| match name {
            "ObjectBuffer" => Some(Resource::Buffer(objects)),
            "AlphaMaskBuffer" => Some(Resource::Buffer(alpha_masks)),
            _ => None,
        })
    }

    /// Bind the pipeline and slot `slot`'s set (inside the render pass; the viewport and
    /// scissor set for the depth-only pipeline stay).
    pub fn record_bind(&self, ctx: &Context, cmd: vk::CommandBuffer, slot: usize) {
        // SAFETY: recording state; the pipeline, its layout and set are alive while the
        // command buffer is.
        unsafe {
            ctx.device.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            ctx.device.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.layout, 0, &[self.sets.sets[slot]], &[]);
        }
    }

    /// Record a draw's push constants.
    pub fn push(&self, ctx: &Context, cmd: vk::CommandBuffer, push: &ShadowMaskPush) {
        // SAFETY: recording state with this pipeline's layout bound.
        unsafe { ctx.device.cmd_push_constants(cmd, self.layout, MASK_STAGES, 0, bytemuck::bytes_of(push)) };
    }

    pub fn destroy(&mut self, ctx: &Context) {
        ml_vk::shader::release_pipeline(ctx, self.pipeline);
        self.pipeline = vk::Pipeline::null();
        self.layout = vk::PipelineLayout::null();
        self.sets.destroy(ctx);
    }
}

impl ml_vk::Release for MaskedPipeline {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_masked_push_keeps_the_affine_model_and_fits_128_bytes() {
        assert_eq!(size_of::<ShadowMaskPush>(), 128);
        let model = Mat4::from_scale_rotation_translation(
            glam::Vec3::new(2.0, 0.5, 3.0),
            glam::Quat::from_rotation_y(0.7),
            glam::Vec3::new(1.0, -2.0, 5.0),
        );
        let push = ShadowMaskPush::new(Mat4::IDENTITY, model, 7);
        let p = glam::Vec4::new(0.3, -1.2, 0.8, 1.0);
        let by_rows = glam::Vec3::from_array(push.model_rows.map(|r| glam::Vec4::from_array(r).dot(p)));
        assert!(by_rows.distance(model.transform_point3(p.truncate())) < 1e-5);
        assert_eq!(push.object, [7, 0, 0, 0]);
    }
}
