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

/// A compute pipeline running `main` of the given SPIR-V with `layout`; `constants` sets
/// 32-bit specialization constants (id, value; a GLSL bool is 0 or 1).
pub fn compute_pipeline(ctx: &Context, spirv: &[u8], layout: vk::PipelineLayout, constants: &[(u32, u32)]) -> Result<vk::Pipeline> {
    let module = module(ctx, spirv)?;
    let entries: Vec<vk::SpecializationMapEntry> = constants
        .iter()
        .enumerate()
        .map(|(i, &(id, _))| vk::SpecializationMapEntry { constant_id: id, offset: (i * 4) as u32, size: 4 })
        .collect();
    let data: Vec<u8> = constants.iter().flat_map(|&(_, v)| v.to_ne_bytes()).collect();
    let spec = vk::SpecializationInfo::default().map_entries(&entries).data(&data);
    let stage = vk::PipelineShaderStageCreateInfo::default()
        .stage(vk::ShaderStageFlags::COMPUTE)
        .module(module)
        .name(c"main")
        .specialization_info(&spec);
    let info = [vk::ComputePipelineCreateInfo::default().stage(stage).layout(layout)];
    // SAFETY: valid module and layout.
    let result = unsafe { ctx.device.create_compute_pipelines(vk::PipelineCache::null(), &info, None) };
    // SAFETY: the module is not needed once the pipeline exists (or failed).
    unsafe { ctx.device.destroy_shader_module(module, None) };
    result.map(|p| p[0]).map_err(|(_, e)| e).ctx("vkCreateComputePipelines")
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
