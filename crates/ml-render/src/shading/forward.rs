//! Forward shading (techniques forward, clustered-cpu, clustered-gpu): one render pass that
//! draws every object and lights each fragment there — over every light (brute force), or
//! over the lights of the fragment's cluster (docs/DESIGN.md#clustered-light-assignment).
//! Leaves the colour target in TRANSFER_SRC_OPTIMAL for the read-back.

use crate::frame_resources::FrameResources;
use crate::pass::{Pass, Recording};
use crate::scene::SceneGpu;
use crate::shading::mesh_raster::{Draw, MeshRaster};
use crate::shading::Shading;
use crate::sync::{shading_reads, Entry, Exit, Use, COLOUR_TARGET};
use crate::targets::Output;
use crate::technique::LightAssignment;
use ml_vk::{vk, Context, VkError};

pub struct Forward {
    raster: MeshRaster,
    /// Draws the cluster-heat legend over the image (debug view cluster-heat; else null).
    legend: vk::Pipeline,
    name: &'static str,
    /// It writes the HDR image instead of the colour target: linear light for the transparent
    /// layers' resolve, or with anti-aliasing the samples' mean for the tone map.
    writes_hdr: bool,
}

impl Forward {
    /// `lights`: loop over every light, the fragment's cluster (CPU lists) or the light grid
    /// near it (GPU); `legend`: draw the heat legend; `name`: the timer's (the technique's).
    pub fn new(
        ctx: &Context,
        scene: &SceneGpu,
        (depth_format, shading): (vk::Format, Shading),
        (lights, legend): (LightAssignment, bool),
        name: &'static str,
    ) -> Result<Forward, VkError> {
        let fragment = match lights {
            LightAssignment::None => &ml_shaders::FORWARD_FRAG,
            LightAssignment::Cpu => &ml_shaders::CLUSTERED_FRAG,
            LightAssignment::Gpu => &ml_shaders::FORWARD_GRID_FRAG,
        };
        let layouts = (scene.textures.set_layout.raw, scene.object_textures.set_layout);
        let raster = MeshRaster::new(ctx, (depth_format, Output::Color, &[]), (fragment, shading, &scene.surface_variants), layouts)?;
        let mut pass = Forward { raster, legend: vk::Pipeline::null(), name, writes_hdr: false };
        pass.writes_hdr = shading.transparency || pass.raster.multisampled();
        if legend {
            let shaders = (&ml_shaders::HEAT_LEGEND_VERT, &ml_shaders::HEAT_LEGEND_FRAG);
            match pass.raster.pipeline(ctx, shaders, Draw::Screen, (pass.raster.pipeline_layout, 0), &[shading.display_constant()]) {
                Ok(p) => pass.legend = p,
                Err(e) => {
                    pass.destroy(ctx);
                    return Err(e);
                }
            }
        }
        Ok(pass)
    }
}

impl Pass for Forward {
    fn timer_name(&self) -> Option<&'static str> {
        Some(self.name)
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.raster.bind_frame(ctx, frame)
    }

    /// The colour target is its render pass's attachment: the pass's external dependencies
    /// order it after the transfers that read it last (the read-back, a window's blit) and
    /// before the transfers after it, and its final layout is TRANSFER_SRC_OPTIMAL
    /// (render_pass.rs). With transparent layers or anti-aliasing it writes the HDR image
    /// instead, which only the pass after it (the layers' resolve, the tone map) reads, ordered
    /// by the render pass's dependencies likewise.
    fn uses(&self) -> Vec<Use> {
        let attachments = vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
            | vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS
            | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let mut uses = shading_reads(vk::PipelineStageFlags::FRAGMENT_SHADER);
        if self.writes_hdr {
            return uses;
        }
        uses.push(Use {
            name: COLOUR_TARGET.0,
            entry: Entry::Chained { stages: attachments | transfer },
            exit: Exit {
                stages: transfer,
                writes: vk::AccessFlags::empty(),
                wrote: true,
                visible: vk::AccessFlags::TRANSFER_READ,
                layout: Some(vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
            },
        });
        uses
    }

    fn record(&self, rec: &Recording) {
        self.raster.begin_and_draw_meshes(rec);
        let d = &rec.ctx.device;
        // SAFETY: recording inside the render pass begun above.
        unsafe {
            if self.legend != vk::Pipeline::null() {
                d.cmd_bind_pipeline(rec.cmd, vk::PipelineBindPoint::GRAPHICS, self.legend);
                d.cmd_draw(rec.cmd, 6, 1, 0, 0);
            }
            d.cmd_end_render_pass(rec.cmd);
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        ml_vk::shader::release_pipeline(ctx, self.legend);
        self.raster.destroy(ctx);
    }
}
