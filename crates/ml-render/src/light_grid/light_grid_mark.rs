//! The light grid's marks (docs/DESIGN.md#the-light-grid): once the opaque surfaces are
//! known (the visibility raster, the G-buffer) and before the build, a thread per pixel marks
//! the cells its surface point's walk will visit (light_grid_mark.glsl), and with transparent
//! layers a thread per node the cells of its point (light_grid_mark_layers.comp). The build
//! then lists only lights of marked cells, which the frame's points may test: at millions of
//! lights most lie far from every visible surface.

use crate::antialiasing::Antialiasing;
use crate::compute_pass::ComputePass;
use crate::frame_resources::{FrameResources, FRAMES_IN_FLIGHT};
use crate::pass::{Pass, Recording};
use crate::sync::{Use, LIGHT_GRID_OCCUPANCY, VISIBILITY_DEPTH};
use crate::transparency::LAYER_BUFFERS;
use ml_vk::commands::memory_barrier;
use ml_vk::{vk, Context, VkError};

/// Threads of the layers' marks (each strides through the nodes).
const LAYER_THREADS: u32 = 1 << 20;

pub struct LightGridMark {
    pass: ComputePass,
    /// The transparent layers' nodes' marks (frames with layers).
    layers: Option<ComputePass>,
    /// Per frame slot: the marks (the build's), cleared before each frame's.
    occupancy: Vec<vk::Buffer>,
    /// The opaque depth is the compute raster's 64-bit buffer (else the depth target).
    depth_buffer: bool,
}

impl LightGridMark {
    /// The marks from the opaque depth (`depth_buffer`: the compute raster's buffer, else the
    /// depth target; its samples: `antialiasing`), and with `layers` from the transparent
    /// layers' nodes (`Some(lobe_textures)`: whether a node keeps the PBR extensions' texels,
    /// a word more).
    pub fn new(ctx: &Context, (depth_buffer, antialiasing): (bool, Antialiasing), layers: Option<bool>) -> Result<LightGridMark, VkError> {
        let (shader, constants) = if depth_buffer {
            (&ml_shaders::LIGHT_GRID_MARK_BUFFER_COMP, vec![antialiasing.constant()])
        } else {
            (&ml_shaders::LIGHT_GRID_MARK_COMP, Vec::new())
        };
        let pass = ComputePass::new(ctx, &[], (shader, &constants))?;
        let mut mark = LightGridMark { pass, layers: None, occupancy: vec![vk::Buffer::null(); FRAMES_IN_FLIGHT], depth_buffer };
        if let Some(lobe_textures) = layers {
            let constants = [antialiasing.constant(), ("LOBE_TEXTURES", u32::from(lobe_textures))];
            match ComputePass::new(ctx, &[], (&ml_shaders::LIGHT_GRID_MARK_LAYERS_COMP, &constants)) {
                Ok(p) => mark.layers = Some(p),
                Err(e) => {
                    mark.pass.destroy(ctx);
                    return Err(e);
                }
            }
        }
        Ok(mark)
    }
}

impl Pass for LightGridMark {
    fn timer_name(&self) -> Option<&'static str> {
        Some("light grid marks")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.occupancy[frame.slot] = frame.raw_buffer(LIGHT_GRID_OCCUPANCY).unwrap_or_default();
        self.pass.bind_frame(ctx, frame)?;
        match &self.layers {
            Some(layers) => layers.bind_frame(ctx, frame),
            None => Ok(()),
        }
    }

    /// Clears and writes the marks; reads the opaque depth (the compute raster's buffer; the
    /// depth target is ordered by the raster's render pass, whose outgoing dependency reaches
    /// compute shaders).
    fn uses(&self) -> Vec<Use> {
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        let marks = (compute | vk::PipelineStageFlags::TRANSFER, rw | vk::AccessFlags::TRANSFER_WRITE);
        let mut uses = vec![Use::buffer(LIGHT_GRID_OCCUPANCY, marks)];
        if self.depth_buffer {
            uses.push(Use::buffer(VISIBILITY_DEPTH, (compute, vk::AccessFlags::SHADER_READ)));
        }
        if self.layers.is_some() {
            // The nodes and their count, as the transparent build left them, and the heads its
            // shader binds with them.
            uses.extend(LAYER_BUFFERS.iter().map(|&name| Use::buffer(name, (compute, vk::AccessFlags::SHADER_READ))));
        }
        uses
    }

    fn record(&self, rec: &Recording) {
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        // SAFETY: recording state outside a render pass; the marks' buffer is alive.
        unsafe { rec.ctx.device.cmd_fill_buffer(rec.cmd, self.occupancy[rec.slot], 0, vk::WHOLE_SIZE, 0) };
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        memory_barrier(rec.ctx, rec.cmd, (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE), (compute, rw));
        self.pass.dispatch(rec.ctx, rec.cmd, rec.slot, (&[], &[]), rec.extent);
        if let Some(layers) = &self.layers {
            memory_barrier(rec.ctx, rec.cmd, (compute, vk::AccessFlags::SHADER_WRITE), (compute, rw));
            layers.dispatch(rec.ctx, rec.cmd, rec.slot, (&[], &[]), vk::Extent2D { width: LAYER_THREADS, height: 1 });
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
        if let Some(layers) = &mut self.layers {
            layers.destroy(ctx);
        }
    }
}
