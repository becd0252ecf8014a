//! The compute raster's large triangles (docs/DESIGN.md#compute-raster): those the phase's
//! culling listed by the 64×64-pixel bins of their box — larger than the split, or crossing
//! the near plane — drawn by a work group per bin (triangle_raster_large.comp), clipped as the
//! hardware clips them, into the same 64-bit buffer as the small ones. One indirect dispatch
//! whose size the culling wrote; in place of the hybrid raster's hardware draw.

use crate::antialiasing::Antialiasing;
use crate::descriptors::FrameSets;
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::pass::{Pass, Recording};
use crate::plan::Phase;
use crate::specialization::{compute_pipeline, Constant};
use crate::sync::{Use, VISIBILITY_DEPTH};
use crate::technique::Raster;
use crate::visibility::meshlet_cull::cull_push;
use crate::visibility::meshlet_scene::{SharedMeshletScene, CULL_COUNTERS, LARGE_BINS, LARGE_TRIANGLES, LAYER_CANDIDATES};
use ml_cpu::gpu_types::{CullCounters, CullPush};
use ml_vk::{shader, vk, Context, VkError};

pub struct TriangleRasterLarge {
    phase: Phase,
    raster: Raster,
    scene: SharedMeshletScene,
    sets: FrameSets,
    pipeline_layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
}

impl TriangleRasterLarge {
    /// `cores`: Shading::cores_constant; `candidates`: it lists the cores' soft samples for
    /// the layers.
    pub fn new(
        ctx: &Context,
        scene: SharedMeshletScene,
        phase: Phase,
        (raster, antialiasing, (cores, candidates)): (Raster, Antialiasing, (Option<Constant>, bool)),
    ) -> Result<TriangleRasterLarge, VkError> {
        let compute = vk::ShaderStageFlags::COMPUTE;
        let shader = &ml_shaders::TRIANGLE_RASTER_LARGE_COMP;
        let pass = TriangleRasterLarge {
            phase,
            raster,
            scene,
            sets: FrameSets::new(ctx, &[(shader, compute)], 0, FRAMES_IN_FLIGHT)?,
            pipeline_layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
        };
        ml_vk::build(ctx, pass, |p| {
            let push = [vk::PushConstantRange::default().stage_flags(compute).size(std::mem::size_of::<CullPush>() as u32)];
            p.pipeline_layout = shader::pipeline_layout(ctx, &[p.sets.layout.raw], &push)?;
            let [tests, masks] = p.scene.borrow().geometry.surface_constants();
            let listing = candidates.then_some(("LAYER_CANDIDATES", 1));
            let constants: Vec<_> = [tests, masks, antialiasing.constant()].into_iter().chain(cores).chain(listing).collect();
            p.pipeline = compute_pipeline(ctx, shader, p.pipeline_layout, &constants)?;
            Ok(())
        })
    }
}

impl Pass for TriangleRasterLarge {
    fn timer_name(&self) -> Option<&'static str> {
        Some(match self.phase {
            Phase::Early => "large triangles (early)",
            Phase::Late => "large triangles (late)",
        })
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let scene = self.scene.borrow();
        self.sets.write(ctx, frame.slot, &|name| scene.buffer(frame, name))
    }

    /// The phase's bins and large triangles, its dispatch (the counters, to which it adds the
    /// pixels it covered and which the late phase reads back), the 64-bit buffer it draws
    /// into.
    fn uses(&self) -> Vec<Use> {
        use vk::AccessFlags as A;
        use vk::PipelineStageFlags as S;
        let rw = A::SHADER_READ | A::SHADER_WRITE;
        let counters = (S::COMPUTE_SHADER | S::DRAW_INDIRECT, rw | A::INDIRECT_COMMAND_READ);
        vec![
            Use::buffer(CULL_COUNTERS, counters),
            Use::buffer(LARGE_BINS, (S::COMPUTE_SHADER, A::SHADER_READ)),
            Use::buffer(LARGE_TRIANGLES, (S::COMPUTE_SHADER, rw)),
            Use::buffer(VISIBILITY_DEPTH, (S::COMPUTE_SHADER, rw)),
            Use::buffer(LAYER_CANDIDATES, (S::COMPUTE_SHADER, rw)),
        ]
    }

    fn record(&self, rec: &Recording) {
        let (ctx, cmd, slot) = (rec.ctx, rec.cmd, rec.slot);
        let d = &ctx.device;
        let scene = self.scene.borrow();
        // The shader reads the phase and the lists' capacity of the culling's push constants.
        let push = cull_push(self.phase, true, self.raster, (&scene, slot), rec.extent);
        let phase = usize::from(self.phase == Phase::Late);
        let dispatch = (std::mem::offset_of!(CullCounters, large) + phase * 16) as u64;
        // SAFETY: recording state outside a render pass; everything bound is alive until the
        // frame's fence signals.
        unsafe {
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline_layout, 0, &[self.sets.sets[slot]], &[]);
            d.cmd_push_constants(cmd, self.pipeline_layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::bytes_of(&push));
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            d.cmd_dispatch_indirect(cmd, scene.frames[slot].counters.raw, dispatch);
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        ml_vk::shader::release_pipeline(ctx, self.pipeline);
        self.pipeline = vk::Pipeline::null();
        self.pipeline_layout = vk::PipelineLayout::null();
        self.sets.destroy(ctx);
        self.scene.borrow_mut().destroy(ctx);
    }
}

impl ml_vk::Release for TriangleRasterLarge {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
