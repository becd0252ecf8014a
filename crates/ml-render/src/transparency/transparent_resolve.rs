//! The transparent resolve, in two compute dispatches: the layers lit, a thread per node in the
//! order their fragments were drawn (transparent_lighting.comp: the same lights, lists, model
//! and shadows as the opaque surfaces), then per pixel sorted and blended back to front over
//! the opaque pass's linear HDR output (the forward pass's, the lighting subpass's, the compute
//! lighting's) and encoded into the colour target (transparent_blend.comp; in place of the
//! deferred techniques' tone map). One pair of shaders for every technique.

use super::{layer_uses, TransparencySettings};
use crate::compute_pass::ComputePass;
use crate::frame_resources::FrameResources;
use crate::pass::{Pass, Recording};
use crate::scene::SceneGpu;
use crate::shading::Shading;
use crate::sync::{shading_reads, Use, HDR_TARGET};
use crate::technique::LightAssignment;
use ml_vk::commands::memory_barrier;
use ml_vk::{vk, Context, VkError};

/// Work groups of the lighting dispatch at most (the least maxComputeWorkGroupCount[0] Vulkan
/// allows): a thread a node, striding on where the pool holds more.
const LIGHTING_GROUPS: u32 = 65535;

pub struct TransparentResolve {
    lighting: ComputePass,
    blend: ComputePass,
    /// A compute lighting pass wrote the HDR image (declared, in GENERAL) — else a render
    /// pass, whose dependencies order it and leave it SHADER_READ_ONLY_OPTIMAL.
    after_compute: bool,
    /// The pool's size per pixel (the lighting dispatch covers the pool).
    settings: TransparencySettings,
}

impl TransparentResolve {
    /// `lights`: the layers are lit by every light, their clusters' (CPU lists) or the light
    /// grid's near them (GPU);
    /// `after_compute`: the HDR image is the compute lighting's.
    pub fn new(
        ctx: &Context,
        scene: &SceneGpu,
        (shading, settings): (Shading, TransparencySettings),
        (lights, after_compute): (LightAssignment, bool),
    ) -> Result<TransparentResolve, VkError> {
        let shader = match lights {
            LightAssignment::None => &ml_shaders::TRANSPARENT_LIGHTING_COMP,
            LightAssignment::Cpu => &ml_shaders::TRANSPARENT_LIGHTING_CLUSTERED_COMP,
            LightAssignment::Gpu => &ml_shaders::TRANSPARENT_LIGHTING_GRID_COMP,
        };
        let lighting = ComputePass::new(ctx, &[scene.textures.set_layout.raw], (shader, &shading.lighting_constants()))?;
        let [blinn_phong, pbr, _] = shading.surface_constants();
        let blend_constants = [blinn_phong, pbr];
        match ComputePass::new(ctx, &[], (&ml_shaders::TRANSPARENT_BLEND_COMP, &blend_constants)) {
            Ok(blend) => Ok(TransparentResolve { lighting, blend, after_compute, settings }),
            Err(e) => {
                let mut lighting = lighting;
                lighting.destroy(ctx);
                Err(e)
            }
        }
    }
}

impl Pass for TransparentResolve {
    fn timer_name(&self) -> Option<&'static str> {
        Some("transparent resolve")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.lighting.bind_frame(ctx, frame, &|name| frame.buffer(name))?;
        let hdr = self.blend.sampled(&frame.targets.hdr, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        self.blend.bind_frame(ctx, frame, &|name| if name == "hdr_image" { hdr } else { frame.buffer(name) })
    }

    /// After the layers' build and the opaque pass that wrote the HDR image.
    fn uses(&self) -> Vec<Use> {
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let mut uses = shading_reads(compute);
        uses.extend(layer_uses(compute));
        if self.after_compute {
            let layout = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
            uses.push(Use::at(HDR_TARGET, (compute, vk::AccessFlags::SHADER_READ), Some(layout)));
        }
        uses.push(ComputePass::colour_use());
        uses
    }

    fn record(&self, rec: &Recording) {
        let (ctx, cmd) = (rec.ctx, rec.cmd);
        let pool = self.settings.nodes(rec.extent.width, rec.extent.height);
        let nodes = pool.min(LIGHTING_GROUPS as u64 * self.lighting.workgroup_size()[0] as u64) as u32;
        let threads = vk::Extent2D { width: nodes.max(1), height: 1 };
        self.lighting.dispatch(ctx, cmd, rec.slot, (&[rec.scene.textures.set], &[]), threads);
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (compute, vk::AccessFlags::SHADER_READ));
        self.blend.record_into_colour_target(ctx, cmd, (rec.slot, &[]), rec.targets.color.raw, rec.extent);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.lighting.destroy(ctx);
        self.blend.destroy(ctx);
    }
}
