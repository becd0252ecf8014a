//! Depth-only render passes and pipelines: the sun's shadow map (scene_textures.rs) and the
//! point-light shadow cubes (omni_shadow.rs). One depth attachment, cleared to 1.0 (the far
//! plane: nothing there) and stored.

use crate::gpu_mesh::{vertex_attributes, vertex_binding};
use ml_vk::{shader, vk, Context, VkError, VkResultExt};

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
    // SAFETY: valid device and create info.
    unsafe { ctx.device.create_render_pass(&info, None) }.ctx("vkCreateRenderPass")
}

/// Depth-only pipeline: positions only, both faces (a shadow caster need not be closed),
/// depth test LESS; `fragment` None writes the rasterised depth.
pub fn pipeline(
    ctx: &Context,
    render_pass: vk::RenderPass,
    layout: vk::PipelineLayout,
    (vertex, fragment): (&[u8], Option<&[u8]>),
) -> Result<vk::Pipeline, VkError> {
    let bindings = [vertex_binding()];
    let attributes = vertex_attributes();
    shader::graphics_pipeline(
        ctx,
        &shader::GraphicsPipelineDesc {
            vertex,
            fragment,
            fragment_constants: &[],
            vertex_input: vk::PipelineVertexInputStateCreateInfo::default()
                .vertex_binding_descriptions(&bindings)
                .vertex_attribute_descriptions(&attributes[..1]),
            rasterization: vk::PipelineRasterizationStateCreateInfo::default()
                .polygon_mode(vk::PolygonMode::FILL)
                .cull_mode(vk::CullModeFlags::NONE)
                .line_width(1.0),
            depth_stencil: vk::PipelineDepthStencilStateCreateInfo::default()
                .depth_test_enable(true)
                .depth_write_enable(true)
                .depth_compare_op(vk::CompareOp::LESS),
            colour_attachments: 0,
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
