//! The raster pass (SPEC §3): one render pass, one subpass. Technique `forward` loops every
//! fragment over every light in a std430 storage buffer; `clustered-*` over the lights of the
//! fragment's cluster (same pass, another fragment shader); `deferred-compute` writes a
//! G-buffer here instead and lights it in a compute pass (deferred.rs).

use crate::gpu_mesh::GpuMesh;
use crate::settings::Technique;
use crate::targets::{Output, COLOR_FORMAT, GBUFFER_NORMAL_FORMAT, GBUFFER_OBJECT_FORMAT};
use ml_cpu::gpu_types::ObjectPush;
use ml_cpu::mesh::Vertex;
use ml_cpu::scene::Object;
use ml_vk::{shader, vk, Context, VkError, VkResultExt};

/// Binding numbers of set 0 (see the shaders).
pub const BINDING_FRAME: u32 = 0;
pub const BINDING_LIGHTS: u32 = 1;
pub const BINDING_CLUSTER_RANGES: u32 = 2;
pub const BINDING_LIGHT_INDICES: u32 = 3;

/// Background of pixels no object covers (linear, before the UNORM store).
pub const CLEAR_COLOR: [f32; 4] = [0.02, 0.02, 0.02, 1.0];

pub struct RasterPass {
    pub render_pass: vk::RenderPass,
    pub set_layout: vk::DescriptorSetLayout,
    pub pipeline_layout: vk::PipelineLayout,
    pub pipeline: vk::Pipeline,
    /// Draws the cluster-heat legend over the image (no depth, no vertex buffer; colour only).
    pub legend_pipeline: vk::Pipeline,
    pub output: Output,
}

/// The two kinds of draw in the pass.
#[derive(Clone, Copy, PartialEq)]
enum Draw {
    /// Scene meshes: vertex buffer, depth test, back-face culling.
    Mesh,
    /// Screen-space overlay made from the vertex index, drawn over everything.
    Overlay,
}

impl RasterPass {
    pub fn new(ctx: &Context, depth_format: vk::Format, technique: Technique) -> Result<RasterPass, VkError> {
        let output = Output::of(technique);
        let pass = RasterPass {
            render_pass: vk::RenderPass::null(),
            set_layout: vk::DescriptorSetLayout::null(),
            pipeline_layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            legend_pipeline: vk::Pipeline::null(),
            output,
        };
        // On failure, destroy what was made (null handles are ignored by vkDestroy*).
        let fragment = match (output, technique.is_clustered()) {
            (Output::GBuffer, _) => ml_shaders::GBUFFER_FRAG,
            (Output::Color, true) => ml_shaders::CLUSTERED_FRAG,
            (Output::Color, false) => ml_shaders::FORWARD_FRAG,
        };
        ml_vk::build(ctx, pass, |p| p.create(ctx, depth_format, fragment, output))
    }

    fn create(&mut self, ctx: &Context, depth_format: vk::Format, fragment: &[u8], output: Output) -> Result<(), VkError> {
        self.render_pass = create_render_pass(ctx, depth_format, output)?;
        let storage = vk::DescriptorType::STORAGE_BUFFER;
        self.set_layout = shader::set_layout(
            ctx,
            &[
                (BINDING_FRAME, vk::DescriptorType::UNIFORM_BUFFER),
                (BINDING_LIGHTS, storage),
                (BINDING_CLUSTER_RANGES, storage),
                (BINDING_LIGHT_INDICES, storage),
            ],
            vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
        )?;
        let push = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)
            .size(std::mem::size_of::<ObjectPush>() as u32)];
        self.pipeline_layout = shader::pipeline_layout(ctx, &[self.set_layout], &push)?;
        let colour_attachments = output.colour_attachments();
        self.pipeline = self.create_pipeline(ctx, ml_shaders::FORWARD_VERT, fragment, Draw::Mesh, colour_attachments)?;
        if output == Output::Color {
            self.legend_pipeline =
                self.create_pipeline(ctx, ml_shaders::HEAT_LEGEND_VERT, ml_shaders::HEAT_LEGEND_FRAG, Draw::Overlay, colour_attachments)?;
        }
        Ok(())
    }

    fn create_pipeline(
        &self,
        ctx: &Context,
        vertex: &[u8],
        fragment: &[u8],
        draw: Draw,
        colour_attachments: usize,
    ) -> Result<vk::Pipeline, VkError> {
        let vert = shader::module(ctx, vertex)?;
        let frag = match shader::module(ctx, fragment) {
            Ok(f) => f,
            Err(e) => {
                // SAFETY: unused module.
                unsafe { ctx.device.destroy_shader_module(vert, None) };
                return Err(e);
            }
        };
        let stages = [
            vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::VERTEX).module(vert).name(c"main"),
            vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::FRAGMENT).module(frag).name(c"main"),
        ];
        let vertex_bindings = [vk::VertexInputBindingDescription::default()
            .binding(0)
            .stride(std::mem::size_of::<Vertex>() as u32)
            .input_rate(vk::VertexInputRate::VERTEX)];
        let vertex_attributes = [
            vk::VertexInputAttributeDescription::default()
                .location(0)
                .binding(0)
                .format(vk::Format::R32G32B32_SFLOAT)
                .offset(std::mem::offset_of!(Vertex, position) as u32),
            vk::VertexInputAttributeDescription::default()
                .location(1)
                .binding(0)
                .format(vk::Format::R32G32B32_SFLOAT)
                .offset(std::mem::offset_of!(Vertex, normal) as u32),
        ];
        let vertex_input = match draw {
            Draw::Mesh => vk::PipelineVertexInputStateCreateInfo::default()
                .vertex_binding_descriptions(&vertex_bindings)
                .vertex_attribute_descriptions(&vertex_attributes),
            Draw::Overlay => vk::PipelineVertexInputStateCreateInfo::default(),
        };
        let input_assembly = vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
        // Meshes wind counter-clockwise seen from outside; the Y-flipped projection keeps that
        // counter-clockwise in Vulkan's framebuffer convention.
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(if draw == Draw::Mesh { vk::CullModeFlags::BACK } else { vk::CullModeFlags::NONE })
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(draw == Draw::Mesh)
            .depth_write_enable(draw == Draw::Mesh)
            .depth_compare_op(vk::CompareOp::LESS);
        let blend_attachments =
            vec![vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA); colour_attachments];
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let info = [vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&input_assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(self.pipeline_layout)
            .render_pass(self.render_pass)
            .subpass(0)];
        // SAFETY: every referenced object is alive.
        let result = unsafe { ctx.device.create_graphics_pipelines(vk::PipelineCache::null(), &info, None) };
        // SAFETY: modules are no longer needed once the pipeline exists (or failed).
        unsafe {
            ctx.device.destroy_shader_module(vert, None);
            ctx.device.destroy_shader_module(frag, None);
        }
        result.map(|p| p[0]).map_err(|(_, e)| e).ctx("vkCreateGraphicsPipelines")
    }

    /// Record the whole pass: clear, draw every object with its push constants (and the
    /// heat-map legend when asked), and leave the colour target in TRANSFER_SRC_OPTIMAL for a
    /// read-back.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        framebuffer: vk::Framebuffer,
        extent: vk::Extent2D,
        set: vk::DescriptorSet,
        meshes: &[GpuMesh],
        objects: &[Object],
        legend: bool,
    ) {
        let d = &ctx.device;
        // Colour attachments clear to the background (G-buffer: zeros), depth to the far plane.
        let colour = vk::ClearValue { color: vk::ClearColorValue { float32: CLEAR_COLOR } };
        let zero = vk::ClearValue { color: vk::ClearColorValue { uint32: [0; 4] } };
        let depth = vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } };
        let clear: Vec<vk::ClearValue> = if self.output == Output::Color { vec![colour, depth] } else { vec![zero, zero, depth] };
        let area = vk::Rect2D { offset: vk::Offset2D::default(), extent };
        let begin = vk::RenderPassBeginInfo::default()
            .render_pass(self.render_pass)
            .framebuffer(framebuffer)
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
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline_layout, 0, &[set], &[]);
            for mesh in meshes {
                d.cmd_bind_vertex_buffers(cmd, 0, &[mesh.vertices.raw], &[0]);
                d.cmd_bind_index_buffer(cmd, mesh.indices.raw, 0, vk::IndexType::UINT32);
                for (index, object) in objects.iter().enumerate().filter(|(_, o)| o.mesh == mesh.kind) {
                    let push = object_push(object, index as u32);
                    d.cmd_push_constants(
                        cmd,
                        self.pipeline_layout,
                        vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                        0,
                        bytemuck::bytes_of(&push),
                    );
                    d.cmd_draw_indexed(cmd, mesh.index_count, 1, 0, 0, 0);
                }
            }
            if legend {
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.legend_pipeline);
                d.cmd_draw(cmd, 6, 1, 0, 0);
            }
            d.cmd_end_render_pass(cmd);
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: no pending work uses these objects; null handles are ignored.
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline(self.legend_pipeline, None);
            ctx.device.destroy_pipeline_layout(self.pipeline_layout, None);
            ctx.device.destroy_descriptor_set_layout(self.set_layout, None);
            ctx.device.destroy_render_pass(self.render_pass, None);
        }
    }
}

/// What a draw of object `index` pushes (also the object buffer's entry for deferred-compute).
pub fn object_push(o: &Object, index: u32) -> ObjectPush {
    let m = &o.material;
    ObjectPush {
        position_scale: [o.position.x, o.position.y, o.position.z, o.scale],
        albedo_roughness: [m.albedo.x, m.albedo.y, m.albedo.z, m.roughness],
        material: [m.metallic, 0.0, 0.0, 0.0],
        ids: [index, 0, 0, 0],
    }
}

fn attachment(format: vk::Format, store: bool, final_layout: vk::ImageLayout) -> vk::AttachmentDescription {
    vk::AttachmentDescription::default()
        .format(format)
        .samples(vk::SampleCountFlags::TYPE_1)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(if store { vk::AttachmentStoreOp::STORE } else { vk::AttachmentStoreOp::DONT_CARE })
        .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
        .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
        .initial_layout(vk::ImageLayout::UNDEFINED)
        .final_layout(final_layout)
}

fn create_render_pass(ctx: &Context, depth_format: vk::Format, output: Output) -> Result<vk::RenderPass, VkError> {
    let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
    let attachments: Vec<vk::AttachmentDescription> = match output {
        // The colour result is copied out; depth is not needed afterwards.
        Output::Color => vec![
            attachment(COLOR_FORMAT, true, vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
            attachment(depth_format, false, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL),
        ],
        // Everything is read by the lighting compute pass.
        Output::GBuffer => vec![
            attachment(GBUFFER_NORMAL_FORMAT, true, read_only),
            attachment(GBUFFER_OBJECT_FORMAT, true, read_only),
            attachment(depth_format, true, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL),
        ],
    };
    let colour_count = output.colour_attachments() as u32;
    let color_refs: Vec<vk::AttachmentReference> = (0..colour_count)
        .map(|attachment| vk::AttachmentReference { attachment, layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL })
        .collect();
    let depth_ref = vk::AttachmentReference { attachment: colour_count, layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL };
    let subpasses = [vk::SubpassDescription::default()
        .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
        .color_attachments(&color_refs)
        .depth_stencil_attachment(&depth_ref)];
    let attachment_stages = vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
        | vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS
        | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS;
    let attachment_writes = vk::AccessFlags::COLOR_ATTACHMENT_WRITE | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE;
    // Who uses the attachments after the pass: the read-back copy, or the lighting compute pass.
    let (after_stage, after_access) = match output {
        Output::Color => (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_READ),
        Output::GBuffer => (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_READ),
    };
    let dependencies = [
        // The targets are reused every other frame: wait for the earlier frame's attachment
        // writes and its readers before clearing them again.
        vk::SubpassDependency::default()
            .src_subpass(vk::SUBPASS_EXTERNAL)
            .dst_subpass(0)
            .src_stage_mask(attachment_stages | after_stage)
            .src_access_mask(attachment_writes)
            .dst_stage_mask(attachment_stages)
            .dst_access_mask(attachment_writes | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ),
        vk::SubpassDependency::default()
            .src_subpass(0)
            .dst_subpass(vk::SUBPASS_EXTERNAL)
            .src_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS)
            .src_access_mask(attachment_writes)
            .dst_stage_mask(after_stage)
            .dst_access_mask(after_access),
    ];
    let info = vk::RenderPassCreateInfo::default().attachments(&attachments).subpasses(&subpasses).dependencies(&dependencies);
    // SAFETY: valid device and create info.
    unsafe { ctx.device.create_render_pass(&info, None) }.ctx("vkCreateRenderPass")
}

impl ml_vk::Release for RasterPass {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
