//! Thin Vulkan plumbing (ash, loaded at run time; memory through gpu-allocator). One small
//! module per object kind; everything a renderer needs and nothing about techniques.
//! Resources are destroyed explicitly with the `Context` that made them: a forgotten one is
//! reported by the validation layer when the device goes away, which the tests count.

pub mod buffer;
pub mod commands;
pub mod context;
pub mod error;
pub mod image;
pub mod shader;
pub mod timing;

pub use ash::vk;
pub use buffer::Buffer;
pub use context::{Context, ContextDesc, DeviceInfo};
pub use error::{VkError, VkResultExt};
pub use image::Image;
pub use timing::GpuTimer;
