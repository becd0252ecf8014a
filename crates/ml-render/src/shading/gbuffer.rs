//! The G-buffer pass of compute lighting (technique deferred-compute): draws every object
//! into the G-buffer (targets.rs GBUFFER: normal, object index, albedo-occlusion and, with
//! object textures, roughness-metallic and emissive) and depth, read next by the compute
//! lighting pass.

use crate::frame_resources::FrameResources;
use crate::pass::{Pass, Recording};
use crate::scene::SceneGpu;
use crate::shading::mesh_raster::MeshRaster;
use crate::shading::Shading;
use crate::sync::{Use, LIGHT_LISTS};
use crate::targets::{gbuffer_images, GBufferKind, Output};
use ml_vk::{vk, Context, VkError};

pub struct GBuffer {
    raster: MeshRaster,
}

impl GBuffer {
    pub fn new(ctx: &Context, scene: &SceneGpu, (depth_format, shading): (vk::Format, Shading)) -> Result<GBuffer, VkError> {
        let layouts = (scene.textures.set_layout.raw, scene.object_textures.set_layout);
        let attachments = (depth_format, Output::GBuffer, gbuffer_images(shading.gbuffer_kind()));
        let fragment = gbuffer_shader(shading.gbuffer_kind());
        Ok(GBuffer { raster: MeshRaster::new(ctx, attachments, (fragment, shading, &scene.surface_variants), layouts)? })
    }
}

/// The G-buffer pass's fragment shader for a G-buffer of `kind` (one output per image).
pub fn gbuffer_shader(kind: GBufferKind) -> &'static ml_shaders::Shader {
    match kind {
        GBufferKind::Base => &ml_shaders::GBUFFER_FRAG,
        GBufferKind::Material => &ml_shaders::GBUFFER_TEXTURED_FRAG,
        GBufferKind::Lobes => &ml_shaders::GBUFFER_LOBES_FRAG,
    }
}

impl Pass for GBuffer {
    fn timer_name(&self) -> Option<&'static str> {
        Some("g-buffer")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.raster.bind_frame(ctx, frame)
    }

    /// Its render pass orders the attachments; its shaders bind the frame's lights with the
    /// rest of set 0 (the surface code reads none), a read like every shading pass's.
    fn uses(&self) -> Vec<Use> {
        let stages = vk::PipelineStageFlags::VERTEX_SHADER | vk::PipelineStageFlags::FRAGMENT_SHADER;
        vec![Use::buffer(LIGHT_LISTS[0], (stages, vk::AccessFlags::SHADER_READ))]
    }

    fn record(&self, rec: &Recording) {
        self.raster.begin_and_draw_meshes(rec);
        // SAFETY: recording inside the render pass begun above.
        unsafe { rec.ctx.device.cmd_end_render_pass(rec.cmd) };
    }

    fn destroy(&mut self, ctx: &Context) {
        self.raster.destroy(ctx);
    }
}
