//! The sun's shadow map (blinn-phong; docs/DESIGN.md#sun-shadow-map): rendered once, when the
//! renderer is made — the sun and the objects do not move (only the point lights do). Depth
//! only, every object, an orthographic view along the sun fitted to the scene
//! (ml_cpu::blinn_phong); 3×3 PCF taps read it through a comparison sampler (scene_textures.rs).

use crate::depth_pass::{self, DepthPassDesc};
use crate::gpu_mesh::{record_draws, GpuMesh};
use ml_cpu::gpu_types::ShadowPush;
use ml_cpu::scene::Scene;
use ml_vk::{shader, vk, Context, Image, VkError, VkResultExt};

/// What the sun's shadow pass draws.
pub struct ShadowInputs<'a> {
    pub scene: &'a Scene,
    pub meshes: &'a [GpuMesh],
    pub view_proj: glam::Mat4,
}

/// Clear `target` to the far plane and, given inputs, draw every object into it from the sun;
/// leave it DEPTH_STENCIL_READ_ONLY_OPTIMAL for the shading passes.
pub(crate) fn render_shadow_map(ctx: &Context, target: &Image, inputs: Option<&ShadowInputs>) -> Result<(), VkError> {
    let d = &ctx.device;
    // The depth writes before every later shader read of the map (frames come after this
    // submission in queue order).
    let render_pass = depth_pass::render_pass(
        ctx,
        &DepthPassDesc {
            format: target.format,
            final_layout: vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL,
            after: vk::PipelineStageFlags::empty(),
            readers: (vk::PipelineStageFlags::FRAGMENT_SHADER | vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_READ),
            view_mask: 0,
        },
    )?;
    let views = [target.view];
    let fb_info = vk::FramebufferCreateInfo::default()
        .render_pass(render_pass)
        .attachments(&views)
        .width(target.extent.width)
        .height(target.extent.height)
        .layers(1);
    let push_size = std::mem::size_of::<ShadowPush>() as u32;
    let push = [vk::PushConstantRange::default().stage_flags(vk::ShaderStageFlags::VERTEX).size(push_size)];
    let mut framebuffer = vk::Framebuffer::null();
    let mut layout = vk::PipelineLayout::null();
    let mut pipeline = vk::Pipeline::null();
    let result = (|| {
        // SAFETY: as above.
        framebuffer = unsafe { d.create_framebuffer(&fb_info, None) }.ctx("vkCreateFramebuffer")?;
        // Only a pass that draws needs the pipeline (a clear does not).
        if inputs.is_some() {
            layout = shader::pipeline_layout(ctx, &[], &push)?;
            pipeline = depth_pass::pipeline(ctx, render_pass, layout, (ml_shaders::SHADOW_VERT.spirv, None))?;
        }
        let area = vk::Rect2D { offset: vk::Offset2D::default(), extent: target.extent };
        ml_vk::commands::one_shot(ctx, |cmd| {
            let begin = vk::RenderPassBeginInfo::default()
                .render_pass(render_pass)
                .framebuffer(framebuffer)
                .render_area(area)
                .clear_values(&depth_pass::CLEAR_FAR);
            // SAFETY: recording state; everything used is alive until the wait in one_shot.
            unsafe {
                d.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE);
                if let Some(s) = inputs {
                    d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline);
                    depth_pass::set_square_viewport(ctx, cmd, target.extent.width);
                    record_draws(
                        ctx,
                        cmd,
                        (s.meshes, &s.scene.objects),
                        |_| 1,
                        |_, object| {
                            let push =
                                ShadowPush { model: object.transform.to_cols_array_2d(), light_view_proj: s.view_proj.to_cols_array_2d() };
                            d.cmd_push_constants(cmd, layout, vk::ShaderStageFlags::VERTEX, 0, bytemuck::bytes_of(&push));
                        },
                    );
                }
                d.cmd_end_render_pass(cmd);
            }
        })
    })();
    // SAFETY: one_shot waited for the GPU (or nothing was submitted); null handles are ignored.
    unsafe {
        d.destroy_pipeline(pipeline, None);
        d.destroy_pipeline_layout(layout, None);
        d.destroy_framebuffer(framebuffer, None);
        d.destroy_render_pass(render_pass, None);
    }
    result
}
