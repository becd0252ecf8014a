//! The raster pass (SPEC §3): one render pass. Technique `forward` loops every fragment over
//! every light in a std430 storage buffer; `clustered-*` over the lights of the fragment's
//! cluster (same pass, another fragment shader); `deferred-compute` writes a G-buffer here and
//! lights it in a compute pass (deferred.rs); `deferred` and `deferred-clustered` are seed
//! 002's pass with two subpasses: subpass 0 writes the G-buffer, subpass 1 reads it as input
//! attachments and shades a full-screen triangle into an HDR target (tone-mapped after).

use crate::gpu_mesh::{record_draws, vertex_attributes, vertex_binding, GpuMesh};
use crate::render_pass;
use crate::settings::{Shading, Technique};
use crate::targets::{gbuffer_images, GBufferImage, Output, Targets};
use ml_cpu::gpu_types::{ObjectData, ObjectPush};
use ml_cpu::scene::Object;
use ml_vk::descriptors::{allocate_set, write_image};
use ml_vk::{shader, vk, Context, VkError};

/// Binding numbers of set 0 (see the shaders).
pub const BINDING_FRAME: u32 = 0;
pub const BINDING_LIGHTS: u32 = 1;
pub const BINDING_CLUSTER_RANGES: u32 = 2;
pub const BINDING_LIGHT_INDICES: u32 = 3;
pub const BINDING_OBJECTS: u32 = 4;
pub const BINDING_LIGHT_CONES: u32 = 10;
/// Bindings of set 2, the lighting subpass's inputs (deferred_frag.glsl; set 1 holds the
/// scene's textures in every pipeline of the pass): depth, then GBUFFER's images in order.
pub const BINDING_INPUT_DEPTH: u32 = 1;
pub const BINDING_INPUT_GBUFFER: u32 = 2;

/// Background of pixels no object covers (linear, before the UNORM store).
pub const CLEAR_COLOR: [f32; 4] = [0.02, 0.02, 0.02, 1.0];

pub struct RasterPass {
    pub render_pass: vk::RenderPass,
    pub set_layout: vk::DescriptorSetLayout,
    pub pipeline_layout: vk::PipelineLayout,
    pub pipeline: vk::Pipeline,
    /// Draws the cluster-heat legend over the image (no depth, no vertex buffer; colour only).
    pub legend_pipeline: vk::Pipeline,
    /// Output::Subpasses: the lighting subpass's pipeline, its layout (sets 0, 1 and 2) and the
    /// layout of set 2 (objects + input attachments); null otherwise.
    pub lighting_pipeline: vk::Pipeline,
    pub lighting_layout: vk::PipelineLayout,
    pub input_set_layout: vk::DescriptorSetLayout,
    pub output: Output,
    shading: Shading,
}

/// The kinds of draw in the pass.
#[derive(Clone, Copy, PartialEq)]
enum Draw {
    /// Scene meshes: vertex buffer, depth test, back-face culling (subpass 0).
    Mesh,
    /// Screen-space overlay made from the vertex index, drawn over everything (subpass 0).
    Overlay,
    /// The full-screen lighting triangle of subpass 1, reading the G-buffer.
    Lighting,
}

/// What one frame's pass draws into and reads.
pub struct PassFrame {
    pub framebuffer: vk::Framebuffer,
    pub extent: vk::Extent2D,
    /// Set 0: uniforms, lights, cluster lists.
    pub set: vk::DescriptorSet,
    /// Set 1: the scene's textures.
    pub textures: vk::DescriptorSet,
    /// Set 2 of the lighting subpass (null without one).
    pub input_set: vk::DescriptorSet,
}

/// The scene's draws: meshes and the objects that use them.
pub struct DrawList<'a> {
    pub meshes: &'a [GpuMesh],
    pub objects: &'a [Object],
    /// Per object: its textures' set (set 2).
    pub object_sets: &'a [vk::DescriptorSet],
}

impl RasterPass {
    /// The pass for a technique and shading model; `textures_layout` is set 1 of every
    /// pipeline (scene_textures.rs), `object_textures_layout` set 2 of the mesh pipelines
    /// (object_textures.rs).
    pub fn new(
        ctx: &Context,
        depth_format: vk::Format,
        (technique, shading): (Technique, Shading),
        (textures_layout, object_textures_layout): (vk::DescriptorSetLayout, vk::DescriptorSetLayout),
    ) -> Result<RasterPass, VkError> {
        let output = Output::of(technique);
        let pass = RasterPass {
            render_pass: vk::RenderPass::null(),
            set_layout: vk::DescriptorSetLayout::null(),
            pipeline_layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            legend_pipeline: vk::Pipeline::null(),
            lighting_pipeline: vk::Pipeline::null(),
            lighting_layout: vk::PipelineLayout::null(),
            input_set_layout: vk::DescriptorSetLayout::null(),
            output,
            shading,
        };
        // On failure, destroy what was made (null handles are ignored by vkDestroy*).
        let fragment = match (output, technique.is_clustered()) {
            (Output::GBuffer | Output::Subpasses, _) if shading.object_textures => ml_shaders::GBUFFER_TEXTURED_FRAG,
            (Output::GBuffer | Output::Subpasses, _) => ml_shaders::GBUFFER_FRAG,
            (Output::Color, true) => ml_shaders::CLUSTERED_FRAG,
            (Output::Color, false) => ml_shaders::FORWARD_FRAG,
        };
        let lighting = match (technique.is_clustered(), shading.object_textures) {
            (false, false) => ml_shaders::DEFERRED_FRAG,
            (true, false) => ml_shaders::DEFERRED_CLUSTERED_FRAG,
            (false, true) => ml_shaders::DEFERRED_TEXTURED_FRAG,
            (true, true) => ml_shaders::DEFERRED_CLUSTERED_TEXTURED_FRAG,
        };
        ml_vk::build(ctx, pass, |p| p.create(ctx, depth_format, (fragment, lighting), (textures_layout, object_textures_layout)))
    }

    fn create(
        &mut self,
        ctx: &Context,
        depth_format: vk::Format,
        (fragment, lighting): (&[u8], &[u8]),
        (textures_layout, object_textures_layout): (vk::DescriptorSetLayout, vk::DescriptorSetLayout),
    ) -> Result<(), VkError> {
        let output = self.output;
        self.render_pass = render_pass::describe(depth_format, output, self.gbuffer()).create(ctx)?;
        let storage = vk::DescriptorType::STORAGE_BUFFER;
        self.set_layout = shader::set_layout(
            ctx,
            &[
                (BINDING_FRAME, vk::DescriptorType::UNIFORM_BUFFER),
                (BINDING_LIGHTS, storage),
                (BINDING_CLUSTER_RANGES, storage),
                (BINDING_LIGHT_INDICES, storage),
                (BINDING_OBJECTS, storage),
                (BINDING_LIGHT_CONES, storage),
            ],
            vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
        )?;
        let push = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)
            .size(std::mem::size_of::<ObjectPush>() as u32)];
        self.pipeline_layout = shader::pipeline_layout(ctx, &[self.set_layout, textures_layout, object_textures_layout], &push)?;
        self.pipeline = self.create_pipeline(ctx, ml_shaders::FORWARD_VERT, fragment, Draw::Mesh)?;
        if output == Output::Color {
            self.legend_pipeline = self.create_pipeline(ctx, ml_shaders::HEAT_LEGEND_VERT, ml_shaders::HEAT_LEGEND_FRAG, Draw::Overlay)?;
        }
        if output == Output::Subpasses {
            use vk::DescriptorType as T;
            let inputs: Vec<(u32, T)> = (BINDING_INPUT_DEPTH..BINDING_INPUT_GBUFFER + self.gbuffer().len() as u32)
                .map(|binding| (binding, T::INPUT_ATTACHMENT))
                .collect();
            self.input_set_layout = shader::set_layout(ctx, &inputs, vk::ShaderStageFlags::FRAGMENT)?;
            self.lighting_layout = shader::pipeline_layout(ctx, &[self.set_layout, textures_layout, self.input_set_layout], &[])?;
            self.lighting_pipeline = self.create_pipeline(ctx, ml_shaders::FULLSCREEN_VERT, lighting, Draw::Lighting)?;
        }
        Ok(())
    }

    /// Set 2 of a frame's lighting subpass: the object buffer and its targets' G-buffer.
    pub fn input_set(&self, ctx: &Context, pool: vk::DescriptorPool, targets: &Targets) -> Result<vk::DescriptorSet, VkError> {
        let set = allocate_set(ctx, pool, self.input_set_layout)?;
        let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let depth = (BINDING_INPUT_DEPTH, targets.depth.view, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL);
        let gbuffer = (BINDING_INPUT_GBUFFER..).zip(&targets.gbuffer).map(|(binding, image)| (binding, image.view, read_only));
        for (binding, view, layout) in [depth].into_iter().chain(gbuffer) {
            let info = vk::DescriptorImageInfo::default().image_view(view).image_layout(layout);
            write_image(ctx, set, binding, vk::DescriptorType::INPUT_ATTACHMENT, info);
        }
        Ok(set)
    }

    fn create_pipeline(&self, ctx: &Context, vertex: &[u8], fragment: &[u8], draw: Draw) -> Result<vk::Pipeline, VkError> {
        let (layout, subpass, colour_attachments) = match draw {
            Draw::Mesh | Draw::Overlay => (self.pipeline_layout, 0, self.output.colour_attachments(self.gbuffer())),
            Draw::Lighting => (self.lighting_layout, 1, 1),
        };
        let bindings = [vertex_binding()];
        let attributes = vertex_attributes();
        let vertex_input = match draw {
            Draw::Mesh => vk::PipelineVertexInputStateCreateInfo::default()
                .vertex_binding_descriptions(&bindings)
                .vertex_attribute_descriptions(&attributes),
            Draw::Overlay | Draw::Lighting => vk::PipelineVertexInputStateCreateInfo::default(),
        };
        // Meshes wind counter-clockwise seen from outside; the Y-flipped projection keeps that
        // counter-clockwise in Vulkan's framebuffer convention.
        let rasterization = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(if draw == Draw::Mesh { vk::CullModeFlags::BACK } else { vk::CullModeFlags::NONE })
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let depth_stencil = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(draw == Draw::Mesh)
            .depth_write_enable(draw == Draw::Mesh)
            .depth_compare_op(vk::CompareOp::LESS);
        // The shading model and point-light shadows, compiled in (shading_model.glsl,
        // omni_shadow.glsl); the legend ignores them.
        let model = self.shading.spec_constants();
        shader::graphics_pipeline(
            ctx,
            &shader::GraphicsPipelineDesc {
                vertex,
                fragment: Some(fragment),
                fragment_constants: &model,
                vertex_input,
                rasterization,
                depth_stencil,
                colour_attachments,
                layout,
                render_pass: self.render_pass,
                subpass,
            },
        )
    }

    /// Record the whole pass: clear, draw every object with its push constants (and the
    /// heat-map legend when asked), and — with two subpasses — light the G-buffer. Leaves the
    /// colour target in TRANSFER_SRC_OPTIMAL for a read-back (Output::Color), or the G-buffer
    /// / HDR image ready for the compute pass that follows.
    pub fn record(&self, ctx: &Context, cmd: vk::CommandBuffer, frame: &PassFrame, draws: &DrawList, legend: bool) {
        let d = &ctx.device;
        // Colour clears to the background, the G-buffer to zeros, depth to the far plane, HDR
        // to alpha 0 ("no object here", see tonemap.comp).
        let colour = vk::ClearValue { color: vk::ClearColorValue { float32: CLEAR_COLOR } };
        let zero = vk::ClearValue { color: vk::ClearColorValue { uint32: [0; 4] } };
        let depth = vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } };
        let mut clear: Vec<vk::ClearValue> = match self.output {
            Output::Color => vec![colour],
            Output::GBuffer | Output::Subpasses => vec![zero; self.gbuffer().len()],
        };
        clear.push(depth);
        if self.output == Output::Subpasses {
            clear.push(zero);
        }
        let extent = frame.extent;
        let area = vk::Rect2D { offset: vk::Offset2D::default(), extent };
        let begin = vk::RenderPassBeginInfo::default()
            .render_pass(self.render_pass)
            .framebuffer(frame.framebuffer)
            .render_area(area)
            .clear_values(&clear);
        let viewport =
            vk::Viewport { x: 0.0, y: 0.0, width: extent.width as f32, height: extent.height as f32, min_depth: 0.0, max_depth: 1.0 };
        // SAFETY: recording state; every handle is alive until the frame's fence signals.
        unsafe {
            d.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            d.cmd_set_viewport(cmd, 0, &[viewport]);
            d.cmd_set_scissor(cmd, 0, &[area]);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline_layout, 0, &[frame.set, frame.textures], &[]);
            // Set 2 (the object's textures) changes only between objects with different ones.
            let mut bound_set = None;
            record_draws(
                ctx,
                cmd,
                (draws.meshes, draws.objects),
                |_| 1,
                |index, o| {
                    let set = draws.object_sets[index as usize];
                    if bound_set.replace(set) != Some(set) {
                        d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline_layout, 2, &[set], &[]);
                    }
                    let push = object_push(o, index);
                    let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
                    d.cmd_push_constants(cmd, self.pipeline_layout, stages, 0, bytemuck::bytes_of(&push));
                },
            );
            if legend {
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.legend_pipeline);
                d.cmd_draw(cmd, 6, 1, 0, 0);
            }
            if self.output == Output::Subpasses {
                d.cmd_next_subpass(cmd, vk::SubpassContents::INLINE);
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.lighting_pipeline);
                let sets = [frame.set, frame.textures, frame.input_set];
                d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.lighting_layout, 0, &sets, &[]);
                d.cmd_draw(cmd, 3, 1, 0, 0);
            }
            d.cmd_end_render_pass(cmd);
        }
    }

    /// The G-buffer images the pass writes (where its output is a G-buffer).
    pub fn gbuffer(&self) -> &'static [GBufferImage] {
        gbuffer_images(self.shading.object_textures)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: no pending work uses these objects; null handles are ignored.
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline(self.legend_pipeline, None);
            ctx.device.destroy_pipeline(self.lighting_pipeline, None);
            ctx.device.destroy_pipeline_layout(self.pipeline_layout, None);
            ctx.device.destroy_pipeline_layout(self.lighting_layout, None);
            ctx.device.destroy_descriptor_set_layout(self.set_layout, None);
            ctx.device.destroy_descriptor_set_layout(self.input_set_layout, None);
            ctx.device.destroy_render_pass(self.render_pass, None);
        }
    }
}

/// Object `o`'s entry in the object buffer.
pub fn object_data(o: &Object) -> ObjectData {
    let normal = glam::Mat4::from_mat3(glam::Mat3::from_mat4(o.transform).inverse().transpose());
    let [albedo_roughness, material, emissive] = material_vectors(o);
    ObjectData { model: o.transform.to_cols_array_2d(), normal_matrix: normal.to_cols_array_2d(), albedo_roughness, material, emissive }
}

/// What a draw of object `o` (at `index`) pushes.
pub fn object_push(o: &Object, index: u32) -> ObjectPush {
    let [albedo_roughness, material, emissive] = material_vectors(o);
    ObjectPush { ids: [index, o.textures.bits(), 0, 0], albedo_roughness, material, emissive }
}

/// The material as the shaders read it: (albedo, roughness), (metallic, occlusion strength,
/// normal scale, 0), (emissive, 0).
fn material_vectors(o: &Object) -> [[f32; 4]; 3] {
    let (m, x) = (&o.material, &o.extras);
    [m.albedo.extend(m.roughness).to_array(), [m.metallic, x.occlusion_strength, x.normal_scale, 0.0], x.emissive.extend(0.0).to_array()]
}

impl ml_vk::Release for RasterPass {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
