//! The visibility raster (docs/DESIGN.md#visibility-buffer): the triangles the culling kept,
//! one indexed draw per phase whose count the GPU wrote (vkCmdDrawIndexedIndirect), from the
//! compacted index buffer, vertices pulled from storage buffers; per pixel the depth and a
//! 32-bit id (visibility.frag). The early phase clears both images, the late one draws the
//! newly visible triangles over them. With the hybrid raster the same draw holds only the
//! triangles it leaves to the hardware (large ones, those crossing the near plane), and
//! their fragments write its 64-bit buffer by atomic min (visibility_atomic.frag) in a pass
//! without attachments — at each of anti-aliasing's samples, the pipeline multisampled.

use crate::antialiasing::Antialiasing;
use crate::descriptors::FrameSets;
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::pass::{Pass, Recording};
use crate::plan::Phase;
use crate::render_pass;
use crate::specialization::{self, Constant};
use crate::sync::{Use, VISIBILITY_DEPTH};
use crate::visibility::meshlet_scene::{SharedMeshletScene, COMPACTED_INDICES, CULL_COUNTERS, DRAW_SLOTS, TRIANGLE_IDS};
use ml_cpu::gpu_types::{CullCounters, DrawIndexedCommand};
use ml_vk::{shader, vk, Context, VkError};

pub struct VisibilityRaster {
    phase: Phase,
    /// The compute raster's hardware half (else the visibility raster).
    atomic: bool,
    scene: SharedMeshletScene,
    render_pass: vk::RenderPass,
    sets: FrameSets,
    pipeline_layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    framebuffers: Vec<vk::Framebuffer>,
}

impl VisibilityRaster {
    /// The pass of `phase`; `atomic`: the compute raster's hardware half; either draws
    /// `antialiasing`'s samples, and transparent objects' cores where `cores`
    /// (Shading::cores_constant) says so.
    pub fn new(
        ctx: &Context,
        scene: SharedMeshletScene,
        (phase, atomic, antialiasing, cores): (Phase, bool, Antialiasing, Option<Constant>),
        depth_format: vk::Format,
    ) -> Result<VisibilityRaster, VkError> {
        // Masked or double-sided objects: both sides drawn, the fragment tests its surface.
        let surface_tests = scene.borrow().geometry.surface_tests;
        let (vert, frag) = match (surface_tests, atomic) {
            (false, false) => (&ml_shaders::VISIBILITY_VERT, &ml_shaders::VISIBILITY_FRAG),
            (false, true) => (&ml_shaders::VISIBILITY_VERT, &ml_shaders::VISIBILITY_ATOMIC_FRAG),
            (true, false) => (&ml_shaders::VISIBILITY_SURFACE_VERT, &ml_shaders::VISIBILITY_SURFACE_FRAG),
            (true, true) => (&ml_shaders::VISIBILITY_SURFACE_VERT, &ml_shaders::VISIBILITY_ATOMIC_SURFACE_FRAG),
        };
        let stages = [(vert, vk::ShaderStageFlags::VERTEX), (frag, vk::ShaderStageFlags::FRAGMENT)];
        let pass = VisibilityRaster {
            phase,
            atomic,
            scene,
            render_pass: vk::RenderPass::null(),
            sets: FrameSets::new(ctx, &stages, 0, FRAMES_IN_FLIGHT)?,
            pipeline_layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            framebuffers: vec![vk::Framebuffer::null(); FRAMES_IN_FLIGHT],
        };
        ml_vk::build(ctx, pass, |p| {
            p.render_pass = if atomic {
                render_pass::visibility_atomic()
            } else {
                render_pass::visibility(depth_format, phase == Phase::Early, antialiasing.sample_count())
            }
            .create(ctx)?;
            let push = [vk::PushConstantRange::default().stage_flags(vk::ShaderStageFlags::FRAGMENT).size(16)];
            p.pipeline_layout = shader::pipeline_layout(ctx, &[p.sets.layout.raw], &push)?;
            let samples = antialiasing.sample_count();
            let constants: Vec<_> = [antialiasing.constant()].into_iter().chain(cores).collect();
            let [vertex_constants, fragment_constants] = specialization::resolve([vert, frag], &constants)?;
            // The G-buffer pass's state: back faces culled (counter-clockwise fronts) — or, with
            // surface tests, by the fragment shader —, depth LESS (the atomic min is the test
            // of the compute raster's half).
            p.pipeline = shader::graphics_pipeline(
                ctx,
                &shader::GraphicsPipelineDesc {
                    vertex: vert.spirv,
                    vertex_constants: &vertex_constants,
                    fragment: Some(frag.spirv),
                    fragment_constants: &fragment_constants,
                    // Vertices are pulled from storage buffers by index.
                    vertex_input: vk::PipelineVertexInputStateCreateInfo::default(),
                    rasterization: vk::PipelineRasterizationStateCreateInfo::default()
                        .polygon_mode(vk::PolygonMode::FILL)
                        .cull_mode(if surface_tests { vk::CullModeFlags::NONE } else { vk::CullModeFlags::BACK })
                        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
                        .line_width(1.0),
                    depth_stencil: vk::PipelineDepthStencilStateCreateInfo::default()
                        .depth_test_enable(!atomic)
                        .depth_write_enable(!atomic)
                        .depth_compare_op(vk::CompareOp::LESS),
                    colour_attachments: usize::from(!atomic),
                    // The attachments' samples; without attachments (the hybrid's half), the
                    // coverage the fragments see (gl_SampleMaskIn).
                    samples,
                    layout: p.pipeline_layout,
                    render_pass: p.render_pass,
                    subpass: 0,
                },
            )?;
            Ok(())
        })
    }
}

impl Pass for VisibilityRaster {
    fn timer_name(&self) -> Option<&'static str> {
        Some(match self.phase {
            Phase::Early if self.atomic => "large triangles (early)",
            Phase::Late if self.atomic => "large triangles (late)",
            Phase::Early => "raster (early)",
            Phase::Late => "raster (late)",
        })
    }

    /// The phase's draw (in the counters), its indices, draw slots and triangle ids — made
    /// visible by a barrier before the render pass, whose own dependencies order its
    /// attachments — and the hybrid's 64-bit buffer, which its fragments write.
    fn uses(&self) -> Vec<Use> {
        use vk::AccessFlags as A;
        use vk::PipelineStageFlags as S;
        let mut uses = vec![
            Use::buffer(CULL_COUNTERS, (S::DRAW_INDIRECT, A::INDIRECT_COMMAND_READ)),
            Use::buffer(COMPACTED_INDICES, (S::VERTEX_INPUT, A::INDEX_READ)),
            Use::buffer(DRAW_SLOTS, (S::VERTEX_SHADER, A::SHADER_READ)),
            Use::buffer(TRIANGLE_IDS, (S::FRAGMENT_SHADER, A::SHADER_READ)),
        ];
        if self.atomic {
            uses.push(Use::buffer(VISIBILITY_DEPTH, (S::FRAGMENT_SHADER, A::SHADER_READ | A::SHADER_WRITE)));
        }
        uses
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let scene = self.scene.borrow();
        self.sets.write(ctx, frame.slot, &|name| scene.buffer(frame, name))?;
        let t = frame.targets;
        // The hybrid's pass has no attachments (nor the images): the colour target's size.
        let views = if self.atomic { Vec::new() } else { vec![t.visibility.view, t.depth.view] };
        render_pass::replace_framebuffer(ctx, &mut self.framebuffers[frame.slot], self.render_pass, &views, t.color.extent)
    }

    fn record(&self, rec: &Recording) {
        let (ctx, cmd, slot, extent) = (rec.ctx, rec.cmd, rec.slot, rec.extent);
        let d = &ctx.device;
        let scene = self.scene.borrow();
        let f = &scene.frames[slot];
        // Ids: 0 (pixels without geometry keep depth 1, which is what says so).
        let clear = [
            vk::ClearValue { color: vk::ClearColorValue { uint32: [0; 4] } },
            vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } },
        ];
        let area = vk::Rect2D { offset: vk::Offset2D::default(), extent };
        let begin = vk::RenderPassBeginInfo::default()
            .render_pass(self.render_pass)
            .framebuffer(self.framebuffers[slot])
            .render_area(area)
            .clear_values(if self.atomic { &[] } else { &clear });
        let viewport =
            vk::Viewport { x: 0.0, y: 0.0, width: extent.width as f32, height: extent.height as f32, min_depth: 0.0, max_depth: 1.0 };
        // CullCounters.draws[phase]; the phase's triangle ids start at 0 (early) or after
        // room for every triangle of the scene (late).
        let phase = usize::from(self.phase == Phase::Late);
        let draw = (std::mem::offset_of!(CullCounters, draws) + phase * std::mem::size_of::<DrawIndexedCommand>()) as u64;
        let first_id = [phase as u32 * scene.geometry.triangles as u32, extent.width, 0, 0];
        // SAFETY: recording state; every handle is alive until the frame's fence signals.
        unsafe {
            d.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            d.cmd_set_viewport(cmd, 0, &[viewport]);
            d.cmd_set_scissor(cmd, 0, &[area]);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline_layout, 0, &[self.sets.sets[slot]], &[]);
            d.cmd_push_constants(cmd, self.pipeline_layout, vk::ShaderStageFlags::FRAGMENT, 0, bytemuck::cast_slice(&first_id));
            d.cmd_bind_index_buffer(cmd, f.indices.raw, 0, vk::IndexType::UINT32);
            d.cmd_draw_indexed_indirect(cmd, f.counters.raw, draw, 1, std::mem::size_of::<DrawIndexedCommand>() as u32);
            d.cmd_end_render_pass(cmd);
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the device is idle; null handles are ignored.
        unsafe {
            for fb in &mut self.framebuffers {
                ctx.device.destroy_framebuffer(*fb, None);
                *fb = vk::Framebuffer::null();
            }
            ml_vk::shader::release_pipeline(ctx, self.pipeline);
        }
        self.pipeline = vk::Pipeline::null();
        self.pipeline_layout = vk::PipelineLayout::null();
        self.render_pass = vk::RenderPass::null();
        self.sets.destroy(ctx);
        self.scene.borrow_mut().destroy(ctx);
    }
}

impl ml_vk::Release for VisibilityRaster {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
