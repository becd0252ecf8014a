//! The sun's shadow map (blinn-phong; docs/DESIGN.md#sun-shadow-map): rendered once, when the
//! renderer is made — the sun and the objects do not move (only the point lights do). Depth
//! only, every object, an orthographic view along the sun fitted to the scene
//! (ml_cpu::blinn_phong), by a render pass or by the compute shadow raster (shadow_raster.rs);
//! 3×3 PCF taps read it through a comparison sampler (scene_textures.rs). In the render pass,
//! alpha-masked objects are drawn after the others by a pipeline of their own whose fragment
//! shader drops what their masks cut out (depth_pass.rs MaskedPipeline; made only for scenes
//! with masked objects).

use crate::depth_pass::{self, DepthPassDesc, MaskedPipeline, ShadowMaskPush};
use crate::error::RenderError;
use crate::gpu_mesh::{record_draws, SceneMeshes};
use crate::scene::meshlets::MeshletGeometryView;
use crate::shadows::shadow_raster::{ShadowRaster, ShadowTarget, ShadowViews};
use crate::shadows::shadow_settings::SunShadowMode;
use ml_cpu::gpu_types::ShadowPush;
use ml_cpu::scene::Scene;
use ml_vk::{shader, vk, Context, GpuTimer, Image, VkError, VkResultExt};

/// What the sun's shadow pass draws.
pub struct ShadowInputs<'a> {
    pub scene: &'a Scene,
    pub meshes: &'a SceneMeshes,
    /// The scene's object buffer (the compute raster reads the transforms there).
    pub objects: vk::Buffer,
    /// The scene's alpha masks (masked objects' shadows have their shape).
    pub alpha_masks: vk::Buffer,
    pub view_proj: glam::Mat4,
    pub mode: SunShadowMode,
    /// The scene's meshlets (the compute raster draws them; SceneGpu builds them for it).
    pub meshlets: Option<MeshletGeometryView>,
}

/// Who reads the map once it is drawn.
const READERS: vk::PipelineStageFlags =
    vk::PipelineStageFlags::from_raw(vk::PipelineStageFlags::FRAGMENT_SHADER.as_raw() | vk::PipelineStageFlags::COMPUTE_SHADER.as_raw());

/// Large triangles the compute raster lists for a work group each (the scene's floor is one);
/// past it, the thread that found one draws it alone.
const LARGE_LIST: u32 = 1 << 16;

/// Draw every object of `inputs` into `target` from the sun as `inputs.mode` says (`target`
/// holds the far plane until then); leave it DEPTH_STENCIL_READ_ONLY_OPTIMAL. Returns the
/// drawing's GPU milliseconds (None without timestamps).
pub(crate) fn draw_shadow_map(ctx: &Context, target: &Image, inputs: &ShadowInputs) -> Result<Option<f64>, RenderError> {
    if inputs.mode == SunShadowMode::Rays {
        // No map is read: the shading traces rays. It is only cleared, for its layout.
        render_shadow_map(ctx, target, None)?;
        return Ok(None);
    }
    let mut timer = GpuTimer::new(ctx, 1)?;
    let drawn = match inputs.mode {
        SunShadowMode::Graphics => render_shadow_map(ctx, target, Some((inputs, &mut timer))).map_err(RenderError::from),
        SunShadowMode::Rays => Ok(()),
        SunShadowMode::Compute => {
            // One orthographic view; its "light" at the origin with radius 1 leaves world
            // positions as they are (omni_raster.glsl).
            let views = (ShadowViews::Ortho, target.extent.width, LARGE_LIST);
            let meshlets =
                inputs.meshlets.ok_or_else(|| RenderError::Internal("the sun's compute shadow raster has no meshlets".into()))?;
            ShadowRaster::new(ctx, meshlets, views, 1).and_then(|mut raster| {
                let shadow_target = ShadowTarget { image: target.raw, readers: Some(READERS) };
                let result = raster.bind(ctx, 0, (inputs.objects, inputs.alpha_masks)).and_then(|()| {
                    ml_vk::commands::one_shot(ctx, |cmd| {
                        timer.reset(ctx, cmd);
                        timer.begin(ctx, cmd, 0);
                        // It ends with a barrier (the map's layout transition), which the
                        // timestamp after it needs on lavapipe (GpuTimer::end).
                        raster.record(ctx, cmd, 0, &[[0.0, 0.0, 0.0, 1.0]], inputs.view_proj, &shadow_target);
                        timer.end(ctx, cmd, 0);
                    })
                });
                raster.destroy(ctx);
                Ok(result?)
            })
        }
    };
    let ms = drawn.and_then(|()| Ok(timer.read_ms(ctx)?));
    timer.destroy(ctx);
    Ok(ms?.map(|passes| passes[0]))
}

/// Clear `target` to the far plane and, given inputs, draw every object into it from the sun
/// (timed by the timer given with them); leave it DEPTH_STENCIL_READ_ONLY_OPTIMAL for the
/// shading passes.
pub(crate) fn render_shadow_map(ctx: &Context, target: &Image, inputs: Option<(&ShadowInputs, &mut GpuTimer)>) -> Result<(), VkError> {
    let d = &ctx.device;
    // The depth writes before every later shader read of the map (frames come after this
    // submission in queue order).
    let render_pass = depth_pass::render_pass(
        ctx,
        &DepthPassDesc {
            format: target.format,
            final_layout: vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL,
            after: vk::PipelineStageFlags::empty(),
            readers: (READERS, vk::AccessFlags::SHADER_READ),
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
    let mut masked_pipeline: Option<MaskedPipeline> = None;
    let result = (|| {
        // SAFETY: as above.
        framebuffer = unsafe { d.create_framebuffer(&fb_info, None) }.ctx("vkCreateFramebuffer")?;
        // Only a pass that draws needs the pipeline (a clear does not), and only one that
        // draws masked objects the masked pipeline.
        if let Some((s, _)) = &inputs {
            layout = shader::pipeline_layout(ctx, &[], &push)?;
            pipeline = depth_pass::pipeline(ctx, render_pass, layout, (ml_shaders::SHADOW_VERT.spirv, None))?;
            if s.scene.objects.iter().any(|o| o.extras.masked()) {
                let shaders = (&ml_shaders::SHADOW_MASKED_VERT, &ml_shaders::SHADOW_MASKED_FRAG);
                let m = masked_pipeline.insert(MaskedPipeline::new(ctx, render_pass, shaders, 1)?);
                m.bind(ctx, 0, (s.objects, s.alpha_masks))?;
            }
        }
        let area = vk::Rect2D { offset: vk::Offset2D::default(), extent: target.extent };
        ml_vk::commands::one_shot(ctx, |cmd| {
            let begin = vk::RenderPassBeginInfo::default()
                .render_pass(render_pass)
                .framebuffer(framebuffer)
                .render_area(area)
                .clear_values(&depth_pass::CLEAR_FAR);
            let mut inputs = inputs;
            if let Some((_, timer)) = inputs.as_mut() {
                timer.reset(ctx, cmd);
                timer.begin(ctx, cmd, 0);
            }
            // SAFETY: recording state; everything used is alive until the wait in one_shot.
            unsafe {
                d.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE);
                if let Some((s, _)) = &inputs {
                    d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline);
                    depth_pass::set_square_viewport(ctx, cmd, target.extent.width);
                    let objects = &s.scene.objects;
                    record_draws(
                        ctx,
                        cmd,
                        (s.meshes, objects),
                        |i| u32::from(!objects[i as usize].extras.masked()),
                        |_, object| {
                            let push =
                                ShadowPush { model: object.transform.to_cols_array_2d(), light_view_proj: s.view_proj.to_cols_array_2d() };
                            d.cmd_push_constants(cmd, layout, vk::ShaderStageFlags::VERTEX, 0, bytemuck::bytes_of(&push));
                        },
                    );
                    if let Some(m) = &masked_pipeline {
                        m.record_bind(ctx, cmd, 0);
                        record_draws(
                            ctx,
                            cmd,
                            (s.meshes, objects),
                            |i| u32::from(objects[i as usize].extras.masked()),
                            |i, object| m.push(ctx, cmd, &ShadowMaskPush::new(s.view_proj, object.transform, i)),
                        );
                    }
                }
                d.cmd_end_render_pass(cmd);
            }
            if let Some((_, timer)) = &inputs {
                timer.end(ctx, cmd, 0);
            }
        })
    })();
    if let Some(m) = &mut masked_pipeline {
        m.destroy(ctx);
    }
    // SAFETY: one_shot waited for the GPU (or nothing was submitted); null handles are ignored.
    unsafe {
        ml_vk::shader::release_pipeline(ctx, pipeline);
        d.destroy_framebuffer(framebuffer, None);
    }
    result
}
