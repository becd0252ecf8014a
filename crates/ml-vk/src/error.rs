use ash::vk;
use thiserror::Error;

/// Everything that can go wrong below the renderer. Messages are one line and say what to do.
#[derive(Debug, Error)]
pub enum VkError {
    #[error("the Vulkan loader (libvulkan.so.1) could not be loaded ({0}): install it, e.g. `apt-get install libvulkan1`")]
    Loader(String),
    #[error("no Vulkan driver found: install one, e.g. `apt-get install mesa-vulkan-drivers` (lavapipe, runs on the CPU) or your GPU vendor's Vulkan driver")]
    NoDriver,
    #[error("no Vulkan device supports what manylights needs (Vulkan 1.2 and a graphics queue){0}")]
    NoSuitableDevice(String),
    #[error("device {index} does not exist: {count} Vulkan device(s) found")]
    DeviceIndex { index: usize, count: usize },
    #[error(
        "validation was requested but the layer VK_LAYER_KHRONOS_validation is not installed: `apt-get install vulkan-validationlayers`"
    )]
    NoValidationLayer,
    /// More than the device allows (a buffer larger than it binds, ...); says what.
    #[error("{0}")]
    DeviceLimit(String),
    /// A swapchain asked of a context made without a window surface.
    #[error("the Vulkan context has no window surface")]
    NoSurface,
    /// The shaders' interface and what Rust binds to it disagree (a bug, found when the
    /// pipeline is made).
    #[error("shader interface: {0}")]
    Interface(String),
    /// A library that records Vulkan commands for us failed (the overlay's renderer).
    #[error("{name}: {message}")]
    Library { name: &'static str, message: String },
    #[error("device '{device}' lacks {what}")]
    Unsupported { device: String, what: String },
    #[error("{what} failed: {result}")]
    Call { what: &'static str, result: vk::Result },
    #[error("GPU memory allocation for {what} failed: {source}")]
    Alloc { what: String, source: gpu_allocator::AllocationError },
}

pub type Result<T> = std::result::Result<T, VkError>;

/// Name the call that returned an error: `device.create_x(..).ctx("vkCreateX")?`.
pub trait VkResultExt<T> {
    fn ctx(self, what: &'static str) -> Result<T>;
}

impl<T> VkResultExt<T> for std::result::Result<T, vk::Result> {
    fn ctx(self, what: &'static str) -> Result<T> {
        self.map_err(|result| VkError::Call { what, result })
    }
}
