//! Compute lighting (technique deferred-compute; docs/DESIGN.md#compute-lighting): the
//! G-buffer pass's images lit by a compute pass through the GPU-built cluster lists — the same
//! BRDF, cluster lookup and light order as the fragment path, on every SM (H100/H200 give
//! graphics work 4 of 132). Its output is the colour target, left in TRANSFER_SRC_OPTIMAL
//! like the forward pass's.

use crate::antialiasing::Antialiasing;
use crate::compute_pass::ComputePass;
use crate::frame_resources::FrameResources;
use crate::pass::{FrameWork, Pass, Recording};
use crate::read_back::HostRead;
use crate::scene::SceneGpu;
use crate::shading::Shading;
use crate::sync::{ray_count_use, shading_reads, Use, RAY_COUNT};
use crate::targets::GBUFFER;
use ml_vk::{vk, Context, VkError};

pub struct ComputeLighting {
    pass: ComputePass,
    /// It writes linear HDR for the transparent layers' resolve (else the colour target).
    layers: bool,
}

impl ComputeLighting {
    pub fn new(ctx: &Context, scene: &SceneGpu, shading: Shading) -> Result<ComputeLighting, VkError> {
        // Set 1: the scene's textures (blinn-phong's shadow map and sky, the shadow cubes).
        let model = shading.compute_lighting_constants();
        // With transparent layers, linear HDR for their resolve; with anti-aliasing, each pixel
        // resolved from the multisampled G-buffer.
        let (shader, constants) = if shading.antialiasing != Antialiasing::Off {
            (&ml_shaders::DEFERRED_LIGHTING_SAMPLES_COMP, [&model[..], &[shading.antialiasing.constant()]].concat())
        } else if shading.transparency {
            (&ml_shaders::DEFERRED_LIGHTING_LINEAR_COMP, model.to_vec())
        } else {
            (&ml_shaders::DEFERRED_LIGHTING_COMP, model.to_vec())
        };
        let pass = ComputePass::new(ctx, &[scene.textures.set_layout.raw], (shader, &constants))?;
        Ok(ComputeLighting { pass, layers: shading.transparency })
    }
}

impl Pass for ComputeLighting {
    fn timer_name(&self) -> Option<&'static str> {
        Some("lighting")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let t = frame.targets;
        let out = if self.layers { &t.hdr } else { &t.color };
        self.pass.bind_frame_to(ctx, frame, out, &|name| {
            // A G-buffer without the material, emissive and lobes images (a scene without object
            // textures, or whose PBR extensions do not vary per point) binds a base image in
            // their place — the object index where the shader reads unsigned integers, else the
            // albedo: the shader, specialised for such scenes, never reads them, but Vulkan
            // wants every binding it names written with a view of its numeric type.
            // Only G-buffer images fall back; any other name nobody provides stays an error.
            let key = name.strip_suffix("_image").filter(|key| GBUFFER.iter().any(|g| g.key == *key))?;
            let g = t.gbuffer_image(key).or_else(|| t.gbuffer_image(if key == "lobes" { "object" } else { "albedo" }))?;
            frame.sampled(g, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)
        })
    }

    /// After the G-buffer pass, the light grid build and the point-light shadows.
    fn uses(&self) -> Vec<Use> {
        let mut uses = shading_reads(vk::PipelineStageFlags::COMPUTE_SHADER);
        uses.push(ComputePass::output_use(self.layers));
        uses.push(ray_count_use());
        uses
    }

    fn record(&self, rec: &Recording) {
        let sets = [rec.scene.textures.set];
        self.pass.record_into_colour_target(rec.ctx, rec.cmd, (rec.slot, &sets), rec.targets.color.raw, rec.extent);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
    }

    fn frame_work(&mut self) -> Option<&mut dyn FrameWork> {
        Some(self)
    }
}

impl FrameWork for ComputeLighting {
    fn host_reads(&self, _slot: usize) -> Vec<HostRead> {
        vec![HostRead::in_place(RAY_COUNT)]
    }
}
