use crate::context::Context;
use crate::error::{Result, VkResultExt};
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
    let module = module(ctx, spirv)?;
    let (entries, data) = specialization(constants);
    let spec = vk::SpecializationInfo::default().map_entries(&entries).data(&data);
    let stage = vk::PipelineShaderStageCreateInfo::default()
        .stage(vk::ShaderStageFlags::COMPUTE)
        .module(module)
        .name(c"main")
        .specialization_info(&spec);
    let stats = ctx.pipeline_stats;
    let flags = if stats { vk::PipelineCreateFlags::CAPTURE_STATISTICS_KHR } else { vk::PipelineCreateFlags::empty() };
    let info = [vk::ComputePipelineCreateInfo::default().flags(flags).stage(stage).layout(layout)];
    // SAFETY: valid module and layout.
    let result = unsafe { ctx.device.create_compute_pipelines(vk::PipelineCache::null(), &info, None) };
    // SAFETY: the module is not needed once the pipeline exists (or failed).
    unsafe { ctx.device.destroy_shader_module(module, None) };
    let pipeline = result.map(|p| p[0]).map_err(|(_, e)| e).ctx("vkCreateComputePipelines")?;
    if stats {
        print_pipeline_stats(ctx, name, constants, pipeline);
    }
    Ok(pipeline)
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
    result.map(|p| p[0]).map_err(|(_, e)| e).ctx("vkCreateGraphicsPipelines")
}

/// A descriptor set layout of `bindings` (binding number, type), all visible to `stages`.
pub fn set_layout(ctx: &Context, bindings: &[(u32, vk::DescriptorType)], stages: vk::ShaderStageFlags) -> Result<vk::DescriptorSetLayout> {
    let bindings: Vec<vk::DescriptorSetLayoutBinding> = bindings
        .iter()
        .map(|&(b, ty)| vk::DescriptorSetLayoutBinding::default().binding(b).descriptor_type(ty).descriptor_count(1).stage_flags(stages))
        .collect();
    // SAFETY: valid device and create info.
    unsafe { ctx.device.create_descriptor_set_layout(&vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings), None) }
        .ctx("vkCreateDescriptorSetLayout")
}

/// A pipeline layout of `set_layouts` and `push_constants`.
pub fn pipeline_layout(
    ctx: &Context,
    set_layouts: &[vk::DescriptorSetLayout],
    push_constants: &[vk::PushConstantRange],
) -> Result<vk::PipelineLayout> {
    let info = vk::PipelineLayoutCreateInfo::default().set_layouts(set_layouts).push_constant_ranges(push_constants);
    // SAFETY: valid device and create info.
    unsafe { ctx.device.create_pipeline_layout(&info, None) }.ctx("vkCreatePipelineLayout")
}
