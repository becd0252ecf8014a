//! The sun's shadow map (blinn-phong; docs/DESIGN.md#sun-shadow-map): drawn by a pass of the
//! first frame after the casters reached the GPU (`ShadowStores::casters_changed` marks it due) —
//! the sun and the objects do not move (only the point lights do), so later frames record
//! nothing. Depth only, every object, an orthographic view along the sun fitted to the scene
//! (ml_cpu::blinn_phong), by a render pass or by the compute shadow raster (shadow_raster.rs);
//! the map is a declared resource (`sync::SUN_MAP`) the shading passes read, so the frame's
//! barriers order the drawing before them. 3×3 PCF taps read it through a comparison sampler
//! (stores.rs). In the render pass, alpha-masked objects are drawn after the others by a
//! pipeline of their own whose fragment shader drops what their masks cut out (depth_pass.rs
//! MaskedPipeline; made only for scenes with masked objects).

use crate::depth_pass::{self, MaskedPipeline, ShadowMaskPush};
use crate::error::RenderError;
use crate::frame_resources::{FrameResources, FRAMES_IN_FLIGHT};
use crate::gpu_mesh::record_draws;
use crate::pass::{Pass, Recording};
use crate::scene::meshlets::MeshletGeometryView;
use crate::scene::{ALPHA_MASKS, OBJECTS};
use crate::shadows::shadow_raster::{ShadowRaster, ShadowTarget, ShadowViews};
use crate::shadows::shadow_settings::SunShadowMode;
use crate::shadows::stores::SharedShadows;
use crate::shadows::sun_map::{self, begin_info, map_render_pass, READERS};
use crate::sync::{Use, SUN_MAP};
use ml_cpu::gpu_types::ShadowPush;
use ml_vk::{shader, vk, Context, Image, VkError};

/// Large triangles the compute raster lists for a work group each (the scene's floor is one);
/// past it, the thread that found one draws it alone.
const LARGE_LIST: u32 = 1 << 16;

/// Who draws the map.
enum Drawer {
    /// A depth-only render pass (and the masked objects' pipeline where there are any).
    Graphics {
        render_pass: vk::RenderPass,
        framebuffer: vk::Framebuffer,
        layout: vk::PipelineLayout,
        pipeline: vk::Pipeline,
        masked: Option<MaskedPipeline>,
    },
    /// The compute shadow raster in one orthographic view.
    Compute(Box<ShadowRaster>),
}

/// The pass that draws the sun's map where it is due.
pub struct SunShadowPass {
    shadows: SharedShadows,
    drawer: Drawer,
}

impl SunShadowPass {
    /// The pass for `mode` (graphics or compute): `masked`, whether some object is alpha
    /// masked; `meshlets`, the scene's (the compute raster draws them).
    pub fn new(
        ctx: &Context,
        shadows: SharedShadows,
        mode: SunShadowMode,
        (masked, meshlets): (bool, Option<MeshletGeometryView>),
    ) -> Result<SunShadowPass, RenderError> {
        let (format, size) = {
            let s = shadows.borrow();
            (s.sun_map().format, s.sun_map_size)
        };
        let drawer = match mode {
            SunShadowMode::Compute => {
                let meshlets = meshlets.ok_or_else(|| RenderError::Internal("the sun's compute shadow raster has no meshlets".into()))?;
                Drawer::Compute(Box::new(ShadowRaster::new(ctx, meshlets, (ShadowViews::Ortho, size, LARGE_LIST), FRAMES_IN_FLIGHT)?))
            }
            // (The sun's rays read no map: `plan` makes no such pass for them.)
            SunShadowMode::Graphics | SunShadowMode::Rays => {
                let mut d = Drawer::Graphics {
                    render_pass: vk::RenderPass::null(),
                    framebuffer: vk::Framebuffer::null(),
                    layout: vk::PipelineLayout::null(),
                    pipeline: vk::Pipeline::null(),
                    masked: None,
                };
                let made = make_graphics(ctx, &mut d, (format, masked), shadows.borrow().sun_map());
                if let Err(e) = made {
                    d.destroy(ctx);
                    return Err(e.into());
                }
                d
            }
        };
        Ok(SunShadowPass { shadows, drawer })
    }
}

/// The graphics drawer's render pass (after the map's last readers), framebuffer and
/// pipelines.
fn make_graphics(ctx: &Context, d: &mut Drawer, (format, masked_objects): (vk::Format, bool), target: &Image) -> Result<(), VkError> {
    let Drawer::Graphics { render_pass, framebuffer, layout, pipeline, masked } = d else { return Ok(()) };
    *render_pass = map_render_pass(ctx, format, READERS)?;
    *framebuffer = sun_map::framebuffer(ctx, *render_pass, target)?;
    let push = [vk::PushConstantRange::default().stage_flags(vk::ShaderStageFlags::VERTEX).size(size_of::<ShadowPush>() as u32)];
    *layout = shader::pipeline_layout(ctx, &[], &push)?;
    *pipeline = depth_pass::pipeline(ctx, *render_pass, *layout, (ml_shaders::SHADOW_VERT.spirv, None))?;
    if masked_objects {
        let shaders = (&ml_shaders::SHADOW_MASKED_VERT, &ml_shaders::SHADOW_MASKED_FRAG);
        *masked = Some(MaskedPipeline::new(ctx, *render_pass, shaders, FRAMES_IN_FLIGHT)?);
    }
    Ok(())
}

impl Drawer {
    fn destroy(&mut self, ctx: &Context) {
        match self {
            Drawer::Graphics { framebuffer, pipeline, masked, .. } => {
                if let Some(m) = masked {
                    m.destroy(ctx);
                }
                // SAFETY: no pending work uses them; null handles are ignored. The render
                // pass and layout are the context cache's.
                unsafe {
                    ml_vk::shader::release_pipeline(ctx, *pipeline);
                    ctx.device.destroy_framebuffer(*framebuffer, None);
                }
                *framebuffer = vk::Framebuffer::null();
                *pipeline = vk::Pipeline::null();
            }
            Drawer::Compute(raster) => raster.destroy(ctx),
        }
    }
}

impl Pass for SunShadowPass {
    fn timer_name(&self) -> Option<&'static str> {
        Some("sun shadow map")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let named = |name| frame.raw_buffer(name).expect("the scene's buffers are in every frame's table");
        let casters = (named(OBJECTS), named(ALPHA_MASKS));
        match &mut self.drawer {
            Drawer::Graphics { masked, .. } => masked.as_ref().map_or(Ok(()), |m| m.bind(ctx, frame.slot, casters)),
            Drawer::Compute(raster) => raster.bind(ctx, frame.slot, casters),
        }
    }

    /// Where the map is due: the render pass orders itself after the shaders that read the
    /// map last and leaves it for them (its external dependencies); the compute raster
    /// overwrites it by a copy (left TRANSFER_DST_OPTIMAL). Nothing in the frames after.
    fn uses(&self) -> Vec<Use> {
        if !self.shadows.borrow().sun_due {
            return Vec::new();
        }
        vec![match self.drawer {
            Drawer::Graphics { .. } => Use::redrawn_for_readers(SUN_MAP, READERS),
            Drawer::Compute(_) => {
                let transfer = (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE);
                Use::overwriting(SUN_MAP, transfer, vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            }
        }]
    }

    fn record(&self, rec: &Recording) {
        let (view_proj, map) = {
            let mut shadows = self.shadows.borrow_mut();
            if !shadows.sun_due {
                return;
            }
            shadows.sun_due = false;
            (shadows.sun_view_proj, (shadows.sun_map().raw, shadows.sun_map().extent))
        };
        let (ctx, cmd) = (rec.ctx, rec.cmd);
        match &self.drawer {
            Drawer::Compute(raster) => {
                // One view; its "light" at the origin with radius 1 leaves world positions as
                // they are (omni_raster.glsl).
                raster.record(ctx, cmd, rec.slot, &[[0.0, 0.0, 0.0, 1.0]], view_proj, &ShadowTarget { image: map.0, readers: None });
            }
            Drawer::Graphics { render_pass, framebuffer, layout, pipeline, masked } => {
                let d = &ctx.device;
                let (meshes, objects) = (&rec.scene.meshes, rec.objects);
                // SAFETY: recording state outside a render pass; everything bound lives until
                // the frame's fence signals.
                unsafe {
                    d.cmd_begin_render_pass(cmd, &begin_info(*render_pass, *framebuffer, map.1), vk::SubpassContents::INLINE);
                    d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, *pipeline);
                    depth_pass::set_square_viewport(ctx, cmd, map.1.width);
                    record_draws(
                        ctx,
                        cmd,
                        (meshes, objects),
                        |i| u32::from(!objects[i as usize].extras.masked()),
                        |_, object| {
                            let push =
                                ShadowPush { model: object.transform.to_cols_array_2d(), light_view_proj: view_proj.to_cols_array_2d() };
                            d.cmd_push_constants(cmd, *layout, vk::ShaderStageFlags::VERTEX, 0, bytemuck::bytes_of(&push));
                        },
                    );
                    if let Some(m) = masked {
                        m.record_bind(ctx, cmd, rec.slot);
                        record_draws(
                            ctx,
                            cmd,
                            (meshes, objects),
                            |i| u32::from(objects[i as usize].extras.masked()),
                            |i, object| m.push(ctx, cmd, &ShadowMaskPush::new(view_proj, object.transform, i)),
                        );
                    }
                    d.cmd_end_render_pass(cmd);
                }
            }
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        self.drawer.destroy(ctx);
    }
}
