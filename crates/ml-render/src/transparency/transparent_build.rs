//! The transparent layers' build: the scene's transparent objects drawn with no attachments,
//! each fragment in front of the opaque depth appended to its pixel's list
//! (transparent_build.frag, layers.glsl). Runs after the opaque raster, before the pass that
//! blends the lists; clears the slot's lists first.

use super::{TransparencyStats, LAYER_BUFFERS};
use crate::descriptors::Resource;
use crate::frame_resources::FrameResources;
use crate::pass::{Pass, Recording, SlotReport};
use crate::report::FrameStats;
use crate::scene::SceneGpu;
use crate::shading::mesh_raster::MeshRaster;
use crate::shading::Shading;
use crate::sync::{Use, VISIBILITY_DEPTH};
use crate::targets::{Output, Targets};
use ml_vk::commands::memory_barrier;
use ml_vk::image::fetch_sampler;
use ml_vk::{vk, Context, VkError};

pub struct TransparentBuild {
    raster: MeshRaster,
    /// Reads the opaque depth image.
    sampler: vk::Sampler,
    /// The opaque depth is the compute raster's 64-bit buffer (else the depth target).
    depth_buffer: bool,
}

impl TransparentBuild {
    pub fn new(ctx: &Context, scene: &SceneGpu, shading: Shading, depth_buffer: bool) -> Result<TransparentBuild, VkError> {
        let fragment = if depth_buffer { &ml_shaders::TRANSPARENT_BUILD_BUFFER_FRAG } else { &ml_shaders::TRANSPARENT_BUILD_FRAG };
        let layouts = (scene.textures.set_layout.raw, scene.object_textures.set_layout);
        // No depth attachment: the format is not used.
        let output = (vk::Format::UNDEFINED, Output::Layers { depth_buffer }, &[][..]);
        let raster = MeshRaster::new(ctx, output, (fragment, shading, &scene.surface_variants), layouts)?;
        let mut pass = TransparentBuild { raster, sampler: vk::Sampler::null(), depth_buffer };
        match fetch_sampler(ctx) {
            Ok(s) => pass.sampler = s,
            Err(e) => {
                pass.destroy(ctx);
                return Err(e);
            }
        }
        Ok(pass)
    }
}

impl Pass for TransparentBuild {
    fn timer_name(&self) -> Option<&'static str> {
        Some("transparent layers")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let depth = vk::DescriptorImageInfo::default()
            .sampler(self.sampler)
            .image_view(frame.targets.depth.view)
            .image_layout(vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL);
        self.raster.bind_frame_with(ctx, frame, &|name| (name == "opaque_depth").then_some(Resource::Image(depth)))
    }

    /// Clears and appends to the lists (after the earlier frame's readers of this slot's); reads
    /// the compute raster's depth. The depth target is ordered by the opaque raster's render
    /// pass, whose outgoing dependency reaches fragment shaders.
    fn uses(&self) -> Vec<Use> {
        let stages = vk::PipelineStageFlags::TRANSFER | vk::PipelineStageFlags::FRAGMENT_SHADER;
        let access = vk::AccessFlags::TRANSFER_WRITE | vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        let mut uses: Vec<Use> = LAYER_BUFFERS.iter().map(|&name| Use::at(name, (stages, access), None)).collect();
        if self.depth_buffer {
            uses.push(Use::at(VISIBILITY_DEPTH, (vk::PipelineStageFlags::FRAGMENT_SHADER, vk::AccessFlags::SHADER_READ), None));
        }
        uses
    }

    fn record(&self, rec: &Recording) {
        let (ctx, cmd) = (rec.ctx, rec.cmd);
        let layers = &rec.targets.layers;
        // SAFETY: recording state outside a render pass; the buffers are alive.
        unsafe {
            ctx.device.cmd_fill_buffer(cmd, layers.heads.raw, 0, vk::WHOLE_SIZE, super::LAYER_END);
            ctx.device.cmd_fill_buffer(cmd, layers.counts.raw, 0, vk::WHOLE_SIZE, 0);
        }
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        memory_barrier(
            ctx,
            cmd,
            (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE),
            (vk::PipelineStageFlags::FRAGMENT_SHADER, rw),
        );
        self.raster.begin_and_draw_meshes(rec);
        // SAFETY: recording inside the render pass begun above.
        unsafe { ctx.device.cmd_end_render_pass(cmd) };
    }

    fn collect(&self, _slot: usize, targets: &Targets, _: &mut SlotReport, stats: &mut FrameStats) {
        let layers = &targets.layers;
        let [fragments, merged] = layers.counts();
        let extent = targets.color.extent;
        stats.set_feature(TransparencyStats {
            fragments: fragments as u64,
            capacity: layers.capacity(),
            pixels: extent.width as u64 * extent.height as u64,
            merged_pixels: merged as u64,
        });
    }

    fn destroy(&mut self, ctx: &Context) {
        // SAFETY: no pending work uses it; a null handle is ignored.
        unsafe { ctx.device.destroy_sampler(self.sampler, None) };
        self.sampler = vk::Sampler::null();
        self.raster.destroy(ctx);
    }
}
