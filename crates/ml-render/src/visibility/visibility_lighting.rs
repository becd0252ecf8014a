//! Lighting from the visibility buffer (technique visibility; docs/DESIGN.md#visibility-buffer):
//! per pixel the triangle the id names is fetched and interpolated, the material evaluated
//! and the clustered light loop run, in compute. Objects' own textures are set 2, bound per
//! texture set: a dispatch per set, each shading its objects' pixels. Its output is the colour
//! target, left in TRANSFER_SRC_OPTIMAL like the other lighting passes'.

use crate::antialiasing::Antialiasing;
use crate::compute_pass::ComputePass;
use crate::frame_resources::FrameResources;
use crate::pass::{FrameWork, Pass, Recording};
use crate::read_back::HostRead;
use crate::scene::SceneGpu;
use crate::shading::Shading;
use crate::sync::{ray_count_use, shading_reads, Use, RAY_COUNT, SURFACE_COLOURS, VISIBILITY_DEPTH};
use crate::visibility::meshlet_scene::SharedMeshletScene;
use ml_vk::{vk, Context, VkError};

pub struct VisibilityLighting {
    pass: ComputePass,
    scene: SharedMeshletScene,
    /// It reads the compute raster's 64-bit buffer (else the raster's images).
    from_buffer: bool,
    /// It writes linear HDR for the transparent layers' resolve (else the colour target).
    layers: bool,
    /// Anti-aliased with transparent layers: it writes the colour target and keeps each
    /// surface's linear colour for the layers' blend.
    surface_colours: bool,
}

impl VisibilityLighting {
    /// The lighting from the hardware raster's images, or with `from_buffer` from the compute
    /// raster's 64-bit buffer.
    pub fn new(
        ctx: &Context,
        gpu: &SceneGpu,
        (scene, from_buffer): (SharedMeshletScene, bool),
        (shading, antialiasing): (Shading, Antialiasing),
    ) -> Result<VisibilityLighting, VkError> {
        let mut constants = shading.compute_lighting_constants().to_vec();
        if from_buffer {
            constants.push(antialiasing.constant());
        }
        let more_sets = [gpu.textures.set_layout.raw, gpu.object_textures.set_layout];
        // With transparent layers, linear HDR for their resolve; anti-aliased, the colour
        // target and the surfaces' colours.
        let surface_colours = shading.transparency && antialiasing != Antialiasing::Off;
        let shader = match (from_buffer, shading.transparency) {
            (true, _) if surface_colours => &ml_shaders::VISIBILITY_LIGHTING_BUFFER_LAYERS_COMP,
            (true, false) => &ml_shaders::VISIBILITY_LIGHTING_BUFFER_COMP,
            (true, true) => &ml_shaders::VISIBILITY_LIGHTING_BUFFER_LINEAR_COMP,
            (false, false) => &ml_shaders::VISIBILITY_LIGHTING_COMP,
            (false, true) => &ml_shaders::VISIBILITY_LIGHTING_LINEAR_COMP,
        };
        let pass = ComputePass::with_push(ctx, &more_sets, (shader, &constants), 16)?;
        let layers = shading.transparency && !surface_colours;
        Ok(VisibilityLighting { pass, scene, from_buffer, layers, surface_colours })
    }
}

impl Pass for VisibilityLighting {
    fn timer_name(&self) -> Option<&'static str> {
        Some("lighting")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let t = frame.targets;
        let scene = self.scene.borrow();
        let out = if self.layers { &t.hdr } else { &t.color };
        self.pass.bind_frame_to(ctx, frame, out, &|name| scene.buffer(frame, name))
    }

    /// After the late raster, the light grid build and the point-light shadows.
    fn uses(&self) -> Vec<Use> {
        let mut uses = shading_reads(vk::PipelineStageFlags::COMPUTE_SHADER);
        uses.push(ComputePass::output_use(self.layers));
        if self.from_buffer {
            uses.push(Use::buffer(VISIBILITY_DEPTH, (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_READ)));
        }
        if self.surface_colours {
            uses.push(Use::buffer(SURFACE_COLOURS, (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_WRITE)));
        }
        uses.push(ray_count_use());
        uses
    }

    fn record(&self, rec: &Recording) {
        let sets = &rec.scene.object_textures.sets;
        let runs: Vec<(Vec<vk::DescriptorSet>, Vec<u8>)> = (0u32..)
            .zip(sets)
            .map(|(i, &set)| (vec![rec.scene.textures.set, set], bytemuck::cast_slice(&[i, 0u32, 0, 0]).to_vec()))
            .collect();
        self.pass.record_runs(rec.ctx, rec.cmd, rec.slot, &runs, (rec.targets.color.raw, rec.extent));
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
        self.scene.borrow_mut().destroy(ctx);
    }

    fn frame_work(&mut self) -> Option<&mut dyn FrameWork> {
        Some(self)
    }
}

impl FrameWork for VisibilityLighting {
    fn host_reads(&self, _slot: usize) -> Vec<HostRead> {
        vec![HostRead::in_place(RAY_COUNT)]
    }
}
