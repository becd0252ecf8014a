use thiserror::Error;

#[derive(Debug, Error)]
pub enum RenderError {
    #[error(transparent)]
    Vulkan(#[from] ml_vk::VkError),
    #[error(transparent)]
    Scene(#[from] ml_cpu::SceneError),
    #[error("{0}")]
    Invalid(String),
}
