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
