//! Shader modules, pipelines and their layouts. Pipelines, pipeline layouts, set layouts and
//! render passes made here are shared through the context (object_cache.rs): the same create
//! info twice gives the same object. Pipelines go back with `release_pipeline`; layouts and
//! render passes belong to the context (never destroy them).

use crate::context::Context;
use crate::error::{Result, VkResultExt};
use crate::object_cache::{Key, COMPUTE_PIPELINE, GRAPHICS_PIPELINE, PIPELINE_LAYOUT, RENDER_PASS, SET_LAYOUT};
use ash::vk;

/// A shader module from SPIR-V bytes (as embedded by ml-shaders).
pub fn module(ctx: &Context, spirv: &[u8]) -> Result<vk::ShaderModule> {
    let words = ash::util::read_spv(&mut std::io::Cursor::new(spirv))
        .map_err(|_| crate::error::VkError::Call { what: "reading SPIR-V", result: vk::Result::ERROR_INVALID_SHADER_NV })?;
    let info = vk::ShaderModuleCreateInfo::default().code(&words);
    // SAFETY: valid SPIR-V words from our build.
    unsafe { ctx.device.create_shader_module(&info, None) }.ctx("vkCreateShaderModule")
}

/// Map entries and data of 32-bit specialization constants (id, value; a GLSL bool is 0 or 1).
/// The ids are the module's own: ml-render resolves the names Rust uses against the shader's
/// reflection before it calls here.
fn specialization(constants: &[(u32, u32)]) -> (Vec<vk::SpecializationMapEntry>, Vec<u8>) {
    let entries = constants
        .iter()
        .enumerate()
        .map(|(i, &(id, _))| vk::SpecializationMapEntry { constant_id: id, offset: (i * 4) as u32, size: 4 })
        .collect();
    (entries, constants.iter().flat_map(|&(_, v)| v.to_ne_bytes()).collect())
}

/// A compute pipeline running `main` of the given SPIR-V with `layout`; `constants` sets
/// 32-bit specialization constants (id, value; a GLSL bool is 0 or 1). `name` (the shader's
/// file) labels its statistics where the context prints them.
pub fn compute_pipeline(
    ctx: &Context,
    name: &str,
    spirv: &[u8],
    layout: vk::PipelineLayout,
    constants: &[(u32, u32)],
) -> Result<vk::Pipeline> {
    let stats = ctx.pipeline_stats;
    let flags = if stats { vk::PipelineCreateFlags::CAPTURE_STATISTICS_KHR } else { vk::PipelineCreateFlags::empty() };
    let mut key = Key::new(COMPUTE_PIPELINE);
    key.bytes(spirv).constants(constants).handle(layout).word(flags.as_raw());
    if let Some(pipeline) = ctx.objects().take_pipeline(&key) {
        return Ok(pipeline);
    }
    let module = module(ctx, spirv)?;
    let (entries, data) = specialization(constants);
    let spec = vk::SpecializationInfo::default().map_entries(&entries).data(&data);
    let stage = vk::PipelineShaderStageCreateInfo::default()
        .stage(vk::ShaderStageFlags::COMPUTE)
        .module(module)
        .name(c"main")
        .specialization_info(&spec);
    let info = [vk::ComputePipelineCreateInfo::default().flags(flags).stage(stage).layout(layout)];
    // SAFETY: valid module and layout.
    let result = unsafe { ctx.device.create_compute_pipelines(vk::PipelineCache::null(), &info, None) };
    // SAFETY: the module is not needed once the pipeline exists (or failed).
    unsafe { ctx.device.destroy_shader_module(module, None) };
    let pipeline = result.map(|p| p[0]).map_err(|(_, e)| e).ctx("vkCreateComputePipelines")?;
    if stats {
        print_pipeline_stats(ctx, name, constants, pipeline);
    }
    Ok(shared(ctx, key, pipeline))
}

/// `pipeline`, just made for `key`, handed out through the context's cache.
fn shared(ctx: &Context, key: Key, pipeline: vk::Pipeline) -> vk::Pipeline {
    let (pipeline, duplicate) = ctx.objects().add_pipeline(key, pipeline);
    // SAFETY: another thread made the same pipeline meanwhile; ours was never used.
    unsafe { ctx.device.destroy_pipeline(duplicate.unwrap_or_default(), None) };
    pipeline
}

/// Hand back a pipeline from `compute_pipeline` or `graphics_pipeline` (null: nothing). The
/// context keeps it a while for whoever asks for the same one (object_cache.rs) and
/// destroys it when that is over: only while no pending work uses it, as destroying would.
pub fn release_pipeline(ctx: &Context, pipeline: vk::Pipeline) {
    if pipeline == vk::Pipeline::null() {
        return;
    }
    let doomed = ctx.objects().release_pipeline(pipeline);
    for p in doomed {
        // SAFETY: no holder is left, and the last one's work is over (the caller's promise).
        unsafe { ctx.device.destroy_pipeline(p, None) };
    }
}

/// One line on stderr per executable of `pipeline` (`Context::pipeline_stats`): its statistics
/// as the driver names and counts them — on NVIDIA the registers a thread takes, which bound
/// how many warps a multiprocessor keeps (the latency a memory-bound pass can hide).
fn print_pipeline_stats(ctx: &Context, name: &str, constants: &[(u32, u32)], pipeline: vk::Pipeline) {
    let ext = ash::khr::pipeline_executable_properties::Device::new(ctx.instance(), &ctx.device);
    let info = vk::PipelineInfoKHR::default().pipeline(pipeline);
    // SAFETY: a pipeline made with CAPTURE_STATISTICS on a device with the extension enabled.
    let executables = match unsafe { ext.get_pipeline_executable_properties(&info) } {
        Ok(executables) => executables,
        Err(e) => return eprintln!("pipeline stats: {name} {constants:?}: not read ({e})"),
    };
    for index in 0..executables.len() as u32 {
        let exe = vk::PipelineExecutableInfoKHR::default().pipeline(pipeline).executable_index(index);
        // SAFETY: as above, index within the executables.
        let stats = match unsafe { ext.get_pipeline_executable_statistics(&exe) } {
            Ok(stats) => stats,
            Err(e) => {
                eprintln!("pipeline stats: {name} {constants:?}: executable {index} not read ({e})");
                continue;
            }
        };
        let values: Vec<String> = stats
            .iter()
            .map(|s| {
                let label = s.name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default();
                // SAFETY: the union member the statistic's format names.
                let value = unsafe {
                    match s.format {
                        vk::PipelineExecutableStatisticFormatKHR::BOOL32 => (s.value.b32 != 0).to_string(),
                        vk::PipelineExecutableStatisticFormatKHR::INT64 => s.value.i64.to_string(),
                        vk::PipelineExecutableStatisticFormatKHR::UINT64 => s.value.u64.to_string(),
                        _ => format!("{:.3}", s.value.f64),
                    }
                };
                format!("{label}={value}")
            })
            .collect();
        eprintln!("pipeline stats: {name} {constants:?}: {}", values.join(", "));
    }
}

/// What differs between the graphics pipelines we make. Fixed for all: `main` entry points,
/// triangle lists, dynamic viewport and scissor, one sample, colour written unblended.
pub struct GraphicsPipelineDesc<'a> {
    pub vertex: &'a [u8],
    /// Specialization constants (id, value) of the vertex stage.
    pub vertex_constants: &'a [(u32, u32)],
    /// None: depth only.
    pub fragment: Option<&'a [u8]>,
    /// Specialization constants (id, value) of the fragment stage.
    pub fragment_constants: &'a [(u32, u32)],
    pub vertex_input: vk::PipelineVertexInputStateCreateInfo<'a>,
    pub rasterization: vk::PipelineRasterizationStateCreateInfo<'a>,
    pub depth_stencil: vk::PipelineDepthStencilStateCreateInfo<'a>,
    pub colour_attachments: usize,
    /// Samples per pixel of the subpass's attachments (`TYPE_1` unless multisampled).
    pub samples: vk::SampleCountFlags,
    pub layout: vk::PipelineLayout,
    pub render_pass: vk::RenderPass,
    pub subpass: u32,
}

/// A graphics pipeline as `desc` says.
pub fn graphics_pipeline(ctx: &Context, desc: &GraphicsPipelineDesc) -> Result<vk::Pipeline> {
    let key = graphics_key(desc);
    if let Some(pipeline) = ctx.objects().take_pipeline(&key) {
        return Ok(pipeline);
    }
    let vert = module(ctx, desc.vertex)?;
    let frag = match desc.fragment.map(|spirv| module(ctx, spirv)).transpose() {
        Ok(f) => f,
        Err(e) => {
            // SAFETY: unused module.
            unsafe { ctx.device.destroy_shader_module(vert, None) };
            return Err(e);
        }
    };
    let (vertex_entries, vertex_data) = specialization(desc.vertex_constants);
    let vertex_spec = vk::SpecializationInfo::default().map_entries(&vertex_entries).data(&vertex_data);
    let (entries, data) = specialization(desc.fragment_constants);
    let spec = vk::SpecializationInfo::default().map_entries(&entries).data(&data);
    let mut stages = vec![vk::PipelineShaderStageCreateInfo::default()
        .stage(vk::ShaderStageFlags::VERTEX)
        .module(vert)
        .name(c"main")
        .specialization_info(&vertex_spec)];
    if let Some(frag) = frag {
        stages.push(
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(frag)
                .name(c"main")
                .specialization_info(&spec),
        );
    }
    let input_assembly = vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let viewport = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
    let multisample = vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(desc.samples);
    let blend_attachments =
        vec![vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA); desc.colour_attachments];
    let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
    let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
    let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
    let info = [vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&desc.vertex_input)
        .input_assembly_state(&input_assembly)
        .viewport_state(&viewport)
        .rasterization_state(&desc.rasterization)
        .multisample_state(&multisample)
        .depth_stencil_state(&desc.depth_stencil)
        .color_blend_state(&blend)
        .dynamic_state(&dynamic)
        .layout(desc.layout)
        .render_pass(desc.render_pass)
        .subpass(desc.subpass)];
    // SAFETY: every referenced object is alive.
    let result = unsafe { ctx.device.create_graphics_pipelines(vk::PipelineCache::null(), &info, None) };
    // SAFETY: modules are no longer needed once the pipeline exists (or failed); null is ignored.
    unsafe {
        ctx.device.destroy_shader_module(vert, None);
        ctx.device.destroy_shader_module(frag.unwrap_or_default(), None);
    }
    let pipeline = result.map(|p| p[0]).map_err(|(_, e)| e).ctx("vkCreateGraphicsPipelines")?;
    Ok(shared(ctx, key, pipeline))
}

/// Every field of `desc` that reaches the create info.
fn graphics_key(desc: &GraphicsPipelineDesc) -> Key {
    let mut key = Key::new(GRAPHICS_PIPELINE);
    key.bytes(desc.vertex).constants(desc.vertex_constants);
    match desc.fragment {
        Some(fragment) => key.word(1u64).bytes(fragment).constants(desc.fragment_constants),
        None => key.word(0u64),
    };
    let input = &desc.vertex_input;
    let rasterization = &desc.rasterization;
    let depth = &desc.depth_stencil;
    assert!(
        input.p_next.is_null() && rasterization.p_next.is_null() && depth.p_next.is_null(),
        "a pipeline state with an extension struct: the cache's key does not hold it"
    );
    // SAFETY: the arrays the create info points at (ash sets pointer and count together).
    let (bindings, attributes) = unsafe {
        (
            raw_slice(input.p_vertex_binding_descriptions, input.vertex_binding_description_count),
            raw_slice(input.p_vertex_attribute_descriptions, input.vertex_attribute_description_count),
        )
    };
    key.word(bindings.len() as u64);
    for b in bindings {
        key.word(b.binding).word(b.stride).word(b.input_rate.as_raw() as u32);
    }
    key.word(attributes.len() as u64);
    for a in attributes {
        key.word(a.location).word(a.binding).word(a.format.as_raw() as u32).word(a.offset);
    }
    key.word(rasterization.depth_clamp_enable)
        .word(rasterization.rasterizer_discard_enable)
        .word(rasterization.polygon_mode.as_raw() as u32)
        .word(rasterization.cull_mode.as_raw())
        .word(rasterization.front_face.as_raw() as u32)
        .word(rasterization.depth_bias_enable)
        .float(rasterization.depth_bias_constant_factor)
        .float(rasterization.depth_bias_clamp)
        .float(rasterization.depth_bias_slope_factor)
        .float(rasterization.line_width);
    key.word(depth.depth_test_enable)
        .word(depth.depth_write_enable)
        .word(depth.depth_compare_op.as_raw() as u32)
        .word(depth.depth_bounds_test_enable)
        .word(depth.stencil_test_enable)
        .float(depth.min_depth_bounds)
        .float(depth.max_depth_bounds);
    for op in [depth.front, depth.back] {
        key.word(op.fail_op.as_raw() as u32)
            .word(op.pass_op.as_raw() as u32)
            .word(op.depth_fail_op.as_raw() as u32)
            .word(op.compare_op.as_raw() as u32)
            .word(op.compare_mask)
            .word(op.write_mask)
            .word(op.reference);
    }
    key.word(desc.colour_attachments as u64).word(desc.samples.as_raw()).handle(desc.layout).handle(desc.render_pass).word(desc.subpass);
    key
}

/// The `count` elements at `ptr` (null or 0: none).
///
/// # Safety
/// `ptr` points at `count` valid elements, or `count` is 0.
unsafe fn raw_slice<'a, T>(ptr: *const T, count: u32) -> &'a [T] {
    if count == 0 || ptr.is_null() {
        &[]
    } else {
        // SAFETY: the caller's promise.
        unsafe { std::slice::from_raw_parts(ptr, count as usize) }
    }
}

/// A descriptor set layout of `bindings` (binding number, type), all visible to `stages`;
/// the context's (never destroy it).
pub fn set_layout(ctx: &Context, bindings: &[(u32, vk::DescriptorType)], stages: vk::ShaderStageFlags) -> Result<vk::DescriptorSetLayout> {
    let bindings: Vec<vk::DescriptorSetLayoutBinding> = bindings
        .iter()
        .map(|&(b, ty)| vk::DescriptorSetLayoutBinding::default().binding(b).descriptor_type(ty).descriptor_count(1).stage_flags(stages))
        .collect();
    set_layout_of(ctx, &bindings)
}

/// The descriptor set layout of `bindings` (no immutable samplers); the context's (never
/// destroy it).
pub fn set_layout_of(ctx: &Context, bindings: &[vk::DescriptorSetLayoutBinding]) -> Result<vk::DescriptorSetLayout> {
    let mut key = Key::new(SET_LAYOUT);
    for b in bindings {
        assert!(b.p_immutable_samplers.is_null(), "immutable samplers: the cache's key does not hold them");
        key.word(b.binding).word(b.descriptor_type.as_raw() as u32).word(b.descriptor_count).word(b.stage_flags.as_raw());
    }
    let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(bindings);
    // SAFETY: valid device and create info; a duplicate was never used.
    let make = || unsafe { ctx.device.create_descriptor_set_layout(&info, None) }.ctx("vkCreateDescriptorSetLayout");
    kept(ctx, key, make, |l| unsafe { ctx.device.destroy_descriptor_set_layout(l, None) })
}

/// The pipeline layout of `set_layouts` (from `set_layout`: the context's, so their handles
/// stand for their bindings) and `push_constants`; the context's (never destroy it).
pub fn pipeline_layout(
    ctx: &Context,
    set_layouts: &[vk::DescriptorSetLayout],
    push_constants: &[vk::PushConstantRange],
) -> Result<vk::PipelineLayout> {
    let mut key = Key::new(PIPELINE_LAYOUT);
    for &l in set_layouts {
        key.handle(l);
    }
    key.word(u64::MAX);
    for r in push_constants {
        key.word(r.stage_flags.as_raw()).word(r.offset).word(r.size);
    }
    let info = vk::PipelineLayoutCreateInfo::default().set_layouts(set_layouts).push_constant_ranges(push_constants);
    // SAFETY: valid device and create info; a duplicate was never used.
    let make = || unsafe { ctx.device.create_pipeline_layout(&info, None) }.ctx("vkCreatePipelineLayout");
    kept(ctx, key, make, |l| unsafe { ctx.device.destroy_pipeline_layout(l, None) })
}

/// The render pass `info` describes (its only extension: multiview); the context's (never
/// destroy it).
pub fn render_pass(ctx: &Context, info: &vk::RenderPassCreateInfo) -> Result<vk::RenderPass> {
    // SAFETY: valid device and create info; a duplicate was never used.
    let make = || unsafe { ctx.device.create_render_pass(info, None) }.ctx("vkCreateRenderPass");
    kept(ctx, render_pass_key(info), make, |p| unsafe { ctx.device.destroy_render_pass(p, None) })
}

/// The context's object of `key` (a layout or render pass, kept for the context's life), made
/// by `make` the first time; `destroy` takes ours where another thread kept one first.
fn kept<T: vk::Handle + Copy>(ctx: &Context, key: Key, make: impl FnOnce() -> Result<T>, destroy: impl FnOnce(T)) -> Result<T> {
    if let Some(raw) = ctx.objects().kept(&key) {
        return Ok(T::from_raw(raw));
    }
    let made = make()?;
    let raw = ctx.objects().keep(key, made.as_raw());
    if raw != made.as_raw() {
        destroy(made);
    }
    Ok(T::from_raw(raw))
}

/// Every field of a render pass's create info (and of its multiview struct).
fn render_pass_key(info: &vk::RenderPassCreateInfo) -> Key {
    let mut key = Key::new(RENDER_PASS);
    let references = |key: &mut Key, refs: &[vk::AttachmentReference]| {
        key.word(refs.len() as u64);
        for r in refs {
            key.word(r.attachment).word(r.layout.as_raw() as u32);
        }
    };
    key.word(info.flags.as_raw());
    // SAFETY: the arrays the create info points at (ash sets pointer and count together; a
    // subpass's resolve array has its colour array's count).
    unsafe {
        for a in raw_slice(info.p_attachments, info.attachment_count) {
            key.word(a.flags.as_raw())
                .word(a.format.as_raw() as u32)
                .word(a.samples.as_raw())
                .word(a.load_op.as_raw() as u32)
                .word(a.store_op.as_raw() as u32)
                .word(a.stencil_load_op.as_raw() as u32)
                .word(a.stencil_store_op.as_raw() as u32)
                .word(a.initial_layout.as_raw() as u32)
                .word(a.final_layout.as_raw() as u32);
        }
        key.word(u64::MAX);
        for s in raw_slice(info.p_subpasses, info.subpass_count) {
            key.word(s.flags.as_raw()).word(s.pipeline_bind_point.as_raw() as u32);
            references(&mut key, raw_slice(s.p_input_attachments, s.input_attachment_count));
            references(&mut key, raw_slice(s.p_color_attachments, s.color_attachment_count));
            let resolve_count = if s.p_resolve_attachments.is_null() { 0 } else { s.color_attachment_count };
            references(&mut key, raw_slice(s.p_resolve_attachments, resolve_count));
            references(&mut key, raw_slice(s.p_depth_stencil_attachment, u32::from(!s.p_depth_stencil_attachment.is_null())));
            key.word(s.preserve_attachment_count as u64);
            for &p in raw_slice(s.p_preserve_attachments, s.preserve_attachment_count) {
                key.word(p);
            }
        }
        key.word(u64::MAX);
        for d in raw_slice(info.p_dependencies, info.dependency_count) {
            key.word(d.src_subpass)
                .word(d.dst_subpass)
                .word(d.src_stage_mask.as_raw())
                .word(d.dst_stage_mask.as_raw())
                .word(d.src_access_mask.as_raw())
                .word(d.dst_access_mask.as_raw())
                .word(d.dependency_flags.as_raw());
        }
        let mut next = info.p_next as *const vk::BaseInStructure;
        while !next.is_null() {
            assert_eq!(
                (*next).s_type,
                vk::StructureType::RENDER_PASS_MULTIVIEW_CREATE_INFO,
                "a render pass extension struct the cache's key does not hold"
            );
            let m = &*(next as *const vk::RenderPassMultiviewCreateInfo);
            key.word(u64::MAX);
            for masks in [raw_slice(m.p_view_masks, m.subpass_count), raw_slice(m.p_correlation_masks, m.correlation_mask_count)] {
                key.word(masks.len() as u64);
                for &mask in masks {
                    key.word(mask);
                }
            }
            for &offset in raw_slice(m.p_view_offsets, m.dependency_count) {
                key.word(offset as u32);
            }
            next = (*next).p_next;
        }
    }
    key
}
