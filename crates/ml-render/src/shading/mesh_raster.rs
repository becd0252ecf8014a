//! What the three raster passes (forward, G-buffer, deferred subpasses) share: their render
//! pass, the pipeline that draws the scene's meshes into its first subpass, its per-frame set 0
//! and framebuffer, and the recording of every object with its push constants. Each pass adds
//! what is its own (the heat legend, the lighting subpass).

use crate::background::Background;
use crate::descriptors::{FrameSets, Resource};
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::gpu_mesh::{record_draws, vertex_attributes, vertex_binding};
use crate::pass::Recording;
use crate::render_pass;
use crate::scene::object_data::{object_push, SurfaceVariant};
use crate::shading::Shading;
use crate::specialization;
use crate::targets::{GBufferImage, Output};
use ml_cpu::gpu_types::ObjectPush;
use ml_shaders::Shader;
use ml_vk::{shader, vk, Context, VkError};

/// Background of pixels no object covers (linear, before the UNORM store).
pub const CLEAR_COLOR: [f32; 4] = [0.02, 0.02, 0.02, 1.0];

/// The kinds of draw in a raster pass.
#[derive(Clone, Copy, PartialEq)]
pub enum Draw {
    /// Scene meshes: vertex buffer, depth test, back-face culling unless double-sided.
    Mesh(SurfaceVariant),
    /// A full-screen or screen-space draw made from the vertex index, no depth.
    Screen,
}

pub struct MeshRaster {
    pub render_pass: vk::RenderPass,
    /// Set 0 of the mesh pipeline, one per frame slot.
    sets: FrameSets,
    pub pipeline_layout: vk::PipelineLayout,
    /// Per `SurfaceVariant::index`: the mesh pipeline (null where the scene has no such object).
    pipelines: [vk::Pipeline; SurfaceVariant::COUNT],
    framebuffers: Vec<vk::Framebuffer>,
    pub output: Output,
    pub gbuffer: &'static [GBufferImage],
    /// The scene's transparent objects are blended in layers: the opaque passes skip them and
    /// the forward pass writes linear HDR (else they are drawn as masks with the rest).
    layers: bool,
    /// Samples per pixel of subpass 0's attachments (anti-aliasing; the transparent layers'
    /// build has none).
    samples: vk::SampleCountFlags,
    /// The background is the environment: the colour target is cleared to alpha 0 for
    /// whoever lays it.
    backdrop: bool,
}

impl MeshRaster {
    /// The render pass for `output` and the mesh pipelines with `fragment`, one per surface
    /// variant of `variants`; sets 1 and 2 are the scene's textures and the object's textures.
    pub fn new(
        ctx: &Context,
        (depth_format, output, gbuffer): (vk::Format, Output, &'static [GBufferImage]),
        (fragment, shading, variants): (&Shader, Shading, &[SurfaceVariant]),
        (textures_layout, object_textures_layout): (vk::DescriptorSetLayout, vk::DescriptorSetLayout),
    ) -> Result<MeshRaster, VkError> {
        let stages = [(&ml_shaders::FORWARD_VERT, vk::ShaderStageFlags::VERTEX), (fragment, vk::ShaderStageFlags::FRAGMENT)];
        let r = MeshRaster {
            render_pass: vk::RenderPass::null(),
            sets: FrameSets::new(ctx, &stages, 0, FRAMES_IN_FLIGHT)?,
            pipeline_layout: vk::PipelineLayout::null(),
            pipelines: [vk::Pipeline::null(); SurfaceVariant::COUNT],
            framebuffers: vec![vk::Framebuffer::null(); FRAMES_IN_FLIGHT],
            output,
            gbuffer,
            layers: shading.transparency,
            samples: match output {
                Output::Color | Output::GBuffer | Output::Subpasses => shading.antialiasing.sample_count(),
                Output::Visibility => vk::SampleCountFlags::TYPE_1,
            },
            backdrop: shading.background == Background::Environment,
        };
        ml_vk::build(ctx, r, |r| {
            r.render_pass = render_pass::describe(depth_format, output, gbuffer, (shading.transparency, r.samples)).create(ctx)?;
            let push = [vk::PushConstantRange::default()
                .stage_flags(vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)
                .size(std::mem::size_of::<ObjectPush>() as u32)];
            r.pipeline_layout = shader::pipeline_layout(ctx, &[r.sets.layout.raw, textures_layout, object_textures_layout], &push)?;
            // Drawn into the colour target, meshes are lit where they are drawn; into a
            // G-buffer, only their surfaces are read (unlit). The passes test masks at each of
            // their samples.
            let constants = match output {
                Output::Color => shading.forward_lighting_constants().to_vec(),
                _ => [shading.surface_constants(), &[shading.antialiasing.constant()]].concat(),
            };
            for &v in variants.iter().chain([&SurfaceVariant::OPAQUE]) {
                if r.pipelines[v.index()] == vk::Pipeline::null() {
                    r.pipelines[v.index()] =
                        r.pipeline(ctx, (&ml_shaders::FORWARD_VERT, fragment), Draw::Mesh(v), (r.pipeline_layout, 0), &constants)?;
                }
            }
            Ok(())
        })
    }

    /// Whether subpass 0's attachments hold several samples a pixel (anti-aliasing).
    pub fn multisampled(&self) -> bool {
        self.samples != vk::SampleCountFlags::TYPE_1
    }

    /// Whether the render pass's last attachment is the HDR image: the lighting subpass's
    /// output, or the forward samples' resolve.
    fn ends_in_hdr(&self) -> bool {
        self.output == Output::Subpasses || (self.output == Output::Color && self.multisampled())
    }

    /// Whether this pass draws `o`: with transparent layers every opaque object (the layers'
    /// build draws the others in compute); without, every object.
    fn draws(&self, o: &ml_cpu::scene::Object) -> bool {
        !(self.layers && o.extras.transparent())
    }

    /// A pipeline of this pass: `draw` kind, in `subpass` with `layout`, specialised by
    /// `constants` (name, value) and, for a mesh draw, by its surface variant's.
    pub fn pipeline(
        &self,
        ctx: &Context,
        (vertex, fragment): (&Shader, &Shader),
        draw: Draw,
        (layout, subpass): (vk::PipelineLayout, u32),
        constants: &[(&str, u32)],
    ) -> Result<vk::Pipeline, VkError> {
        let colour_attachments = if subpass == 0 { self.output.colour_attachments(self.gbuffer) } else { 1 };
        // The deferred lighting subpass writes one HDR value a pixel.
        let samples = if subpass == 0 { self.samples } else { vk::SampleCountFlags::TYPE_1 };
        let bindings = [vertex_binding()];
        let attributes = vertex_attributes();
        let mesh = matches!(draw, Draw::Mesh(_));
        let vertex_input = match draw {
            Draw::Mesh(_) => vk::PipelineVertexInputStateCreateInfo::default()
                .vertex_binding_descriptions(&bindings)
                .vertex_attribute_descriptions(&attributes),
            Draw::Screen => vk::PipelineVertexInputStateCreateInfo::default(),
        };
        // Meshes wind counter-clockwise seen from outside; the Y-flipped projection keeps that
        // counter-clockwise in Vulkan's framebuffer convention.
        let rasterization = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(match draw {
                Draw::Mesh(v) if !v.double_sided => vk::CullModeFlags::BACK,
                _ => vk::CullModeFlags::NONE,
            })
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let depth = mesh;
        let depth_stencil = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(depth)
            .depth_write_enable(depth)
            .depth_compare_op(vk::CompareOp::LESS);
        let mut constants = constants.to_vec();
        if let Draw::Mesh(v) = draw {
            constants.extend(v.spec_constants());
        }
        let [vertex_constants, fragment_constants] = specialization::resolve([vertex, fragment], &constants)?;
        shader::graphics_pipeline(
            ctx,
            &shader::GraphicsPipelineDesc {
                vertex: vertex.spirv,
                vertex_constants: &vertex_constants,
                fragment: Some(fragment.spirv),
                fragment_constants: &fragment_constants,
                vertex_input,
                rasterization,
                depth_stencil,
                colour_attachments,
                samples,
                layout,
                render_pass: self.render_pass,
                subpass,
            },
        )
    }

    /// Slot `frame.slot`'s framebuffer over `frame.targets` (attachment order: render_pass.rs)
    /// and its set 0.
    pub fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.bind_frame_with(ctx, frame, &|_| None)
    }

    /// `bind_frame`, with set-0 resources of the pass's own that `extra` names (images).
    pub fn bind_frame_with(
        &mut self,
        ctx: &Context,
        frame: &FrameResources,
        extra: &dyn Fn(&str) -> Option<Resource>,
    ) -> Result<(), VkError> {
        self.sets.write(ctx, frame.slot, &|name| extra(name).or_else(|| frame.resource(name)))?;
        let t = frame.targets;
        let mut views: Vec<vk::ImageView> = match self.output {
            Output::Color if self.layers => vec![t.hdr.view],
            Output::Color if self.multisampled() => vec![t.colour_samples.view],
            Output::Color => vec![t.color.view],
            _ => t.gbuffer.iter().map(|g| g.view).collect(),
        };
        views.push(t.depth.view);
        if self.ends_in_hdr() {
            views.push(t.hdr.view);
        }
        render_pass::replace_framebuffer(ctx, &mut self.framebuffers[frame.slot], self.render_pass, &views, t.color.extent)
    }

    /// Begin the render pass (colour to the background, the G-buffer to zeros, depth to the far
    /// plane, HDR to alpha 0 — "no object here", see tonemap.comp) and draw every object it
    /// draws (`draws`) with its push constants; the caller records the rest and ends the pass.
    pub fn begin_and_draw_meshes(&self, rec: &Recording) {
        let (ctx, cmd) = (rec.ctx, rec.cmd);
        let d = &ctx.device;
        let colour = vk::ClearValue { color: vk::ClearColorValue { float32: CLEAR_COLOR } };
        let zero = vk::ClearValue { color: vk::ClearColorValue { uint32: [0; 4] } };
        let depth = vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } };
        let mut clear: Vec<vk::ClearValue> = match self.output {
            // Alpha 0: no surface at the sample (the tone map shows the background there).
            // So too where the backdrop pass fills it (background.rs).
            Output::Color if self.layers || self.multisampled() || self.backdrop => vec![zero],
            Output::Color | Output::Visibility => vec![colour],
            Output::GBuffer | Output::Subpasses => vec![zero; self.gbuffer.len()],
        };
        clear.push(depth);
        // (The forward samples' resolve is not cleared.)
        if self.ends_in_hdr() {
            clear.push(zero);
        }
        let extent = rec.extent;
        let area = vk::Rect2D { offset: vk::Offset2D::default(), extent };
        let begin = vk::RenderPassBeginInfo::default()
            .render_pass(self.render_pass)
            .framebuffer(self.framebuffers[rec.slot])
            .render_area(area)
            .clear_values(&clear);
        let viewport =
            vk::Viewport { x: 0.0, y: 0.0, width: extent.width as f32, height: extent.height as f32, min_depth: 0.0, max_depth: 1.0 };
        let scene = rec.scene;
        let sets = [self.sets.sets[rec.slot], scene.textures.set];
        // SAFETY: recording state; every handle is alive until the frame's fence signals.
        unsafe {
            d.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipelines[SurfaceVariant::OPAQUE.index()]);
            d.cmd_set_viewport(cmd, 0, &[viewport]);
            d.cmd_set_scissor(cmd, 0, &[area]);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline_layout, 0, &sets, &[]);
            // Set 2 (the object's textures) changes only between objects with different ones,
            // the pipeline only between objects of different surface variants.
            let mut bound_set = None;
            let mut bound_variant = SurfaceVariant::OPAQUE;
            record_draws(
                ctx,
                cmd,
                (&scene.meshes, rec.objects),
                |index| u32::from(self.draws(&rec.objects[index as usize])),
                |index, o| {
                    let variant = SurfaceVariant::of(o);
                    if variant != bound_variant {
                        // Made for every variant the scene's objects have (SceneGpu refuses
                        // replaced objects of another).
                        d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipelines[variant.index()]);
                        bound_variant = variant;
                    }
                    let set = scene.object_textures.per_object[index as usize];
                    if bound_set.replace(set) != Some(set) {
                        d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline_layout, 2, &[set], &[]);
                    }
                    let push = object_push(o, index);
                    let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
                    d.cmd_push_constants(cmd, self.pipeline_layout, stages, 0, bytemuck::bytes_of(&push));
                },
            );
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: no pending work uses these objects; null handles are ignored.
        unsafe {
            for fb in self.framebuffers.drain(..) {
                ctx.device.destroy_framebuffer(fb, None);
            }
            for p in self.pipelines {
                ml_vk::shader::release_pipeline(ctx, p);
            }
        }
        self.sets.destroy(ctx);
    }
}

impl ml_vk::Release for MeshRaster {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
