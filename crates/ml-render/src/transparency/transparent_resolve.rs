//! The transparent resolve, in two compute dispatches: the layers lit, a thread per node in the
//! order their fragments were drawn (transparent_lighting.comp: the same lights, lists, model
//! and shadows as the opaque surfaces), then per pixel sorted and blended back to front over
//! the opaque pass's linear HDR output (the forward pass's, the lighting subpass's, the compute
//! lighting's) and encoded into the colour target (transparent_blend.comp; in place of the
//! deferred techniques' tone map). One pair of shaders for every technique. With
//! anti-aliasing (the visibility technique), the lighting resolved the colour target and kept
//! its surfaces' colours: the blend redoes the pixels with layers, sample by sample
//! (transparent_blend_samples.comp).

use super::{layer_uses, TransparencySettings};
use crate::antialiasing::Antialiasing;
use crate::compute_pass::ComputePass;
use crate::frame_resources::FrameResources;
use crate::pass::{Pass, Recording};
use crate::scene::SceneGpu;
use crate::shading::Shading;
use crate::sync::{shading_reads, Use, COLOUR_TARGET, HDR_TARGET, SURFACE_COLOURS, VISIBILITY_DEPTH};
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
    /// Anti-aliased: the blend reads the samples and the surfaces' colours, and rewrites the
    /// colour target's pixels that have layers.
    samples: bool,
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
        // The nodes keep their samples (layers.glsl): every pass of theirs knows the count.
        let samples = shading.antialiasing.constant();
        let lighting_constants = [&shading.lighting_constants()[..], &[samples]].concat();
        let lighting = ComputePass::new(ctx, &[scene.textures.set_layout.raw], (shader, &lighting_constants))?;
        // The nodes' size (with the PBR extensions' texels where they vary per point).
        let surface = |name| (name, shading.constant(name).expect("every surface constant is set"));
        let [blinn_phong, pbr, lobe_textures] = ["MODEL_BLINN_PHONG", "MODEL_PBR", "LOBE_TEXTURES"].map(surface);
        let antialiased = shading.antialiasing != Antialiasing::Off;
        // Set 1 (the scene's textures) for the background's environment.
        let textures = [scene.textures.set_layout.raw];
        let background = shading.background.constant();
        let blend = if antialiased {
            ComputePass::new(
                ctx,
                &textures,
                (&ml_shaders::TRANSPARENT_BLEND_SAMPLES_COMP, &[blinn_phong, pbr, samples, background, lobe_textures]),
            )
        } else {
            ComputePass::new(ctx, &textures, (&ml_shaders::TRANSPARENT_BLEND_COMP, &[blinn_phong, pbr, background, lobe_textures]))
        };
        match blend {
            Ok(blend) => Ok(TransparentResolve { lighting, blend, after_compute, settings, samples: antialiased }),
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
        self.lighting.bind_frame(ctx, frame)?;
        // (Anti-aliased, the blend reads no HDR image: none is asked for.)
        self.blend.bind_frame(ctx, frame)
    }

    /// After the layers' build and the opaque pass that wrote the HDR image.
    fn uses(&self) -> Vec<Use> {
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let mut uses = shading_reads(compute);
        uses.extend(layer_uses(compute));
        if self.samples {
            let read = (compute, vk::AccessFlags::SHADER_READ);
            uses.push(Use::buffer(VISIBILITY_DEPTH, read));
            uses.push(Use::buffer(SURFACE_COLOURS, read));
            // The pixels without layers keep the lighting's colour.
            let write = (compute, vk::AccessFlags::SHADER_WRITE);
            uses.push(Use::image(COLOUR_TARGET, write, vk::ImageLayout::GENERAL));
            return uses;
        }
        if self.after_compute {
            let layout = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
            uses.push(Use::image(HDR_TARGET, (compute, vk::AccessFlags::SHADER_READ), layout));
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
        self.blend.record_into_colour_target(ctx, cmd, (rec.slot, &[rec.scene.textures.set]), rec.targets.color.raw, rec.extent);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.lighting.destroy(ctx);
        self.blend.destroy(ctx);
    }
}
