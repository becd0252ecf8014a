//! Thin Vulkan plumbing (ash, loaded at run time; memory through gpu-allocator). One small
//! module per object kind; everything a renderer needs and nothing about techniques.
//! Resources are destroyed explicitly with the `Context` that made them: a forgotten one is
//! reported by the validation layer when the device goes away, which the tests count.

pub mod buffer;
pub mod commands;
pub mod context;
pub mod descriptors;
pub mod driver_env;
pub mod error;
pub mod image;
pub mod object_cache;
pub mod shader;
pub mod swapchain;
pub mod timing;

pub use ash::vk;
pub use buffer::Buffer;
pub use context::{Context, ContextDesc, DeviceInfo, OptionalFeatures, Surface, WindowHandles};
pub use error::{VkError, VkResultExt};
pub use gpu_allocator::MemoryLocation;
pub use image::{Image, ImageShape};
pub use timing::GpuTimer;

/// Objects made of several Vulkan objects release them all, skipping parts never made (null).
pub trait Release {
    fn release(&mut self, ctx: &Context);
}

/// `made`, or — if it failed — its error after releasing `earlier` (newest first): for a
/// sequence of objects each of which needs the ones before it.
pub fn release_on_error<T, E>(ctx: &Context, made: Result<T, E>, earlier: &mut [&mut dyn Release]) -> Result<T, E> {
    made.inspect_err(|_| {
        for r in earlier.iter_mut().rev() {
            r.release(ctx);
        }
    })
}

/// Finish building `value` (which starts with null parts) with `create`; if that fails,
/// release whatever it made before returning the error.
pub fn build<T: Release, E>(ctx: &Context, mut value: T, create: impl FnOnce(&mut T) -> Result<(), E>) -> Result<T, E> {
    match create(&mut value) {
        Ok(()) => Ok(value),
        Err(e) => {
            value.release(ctx);
            Err(e)
        }
    }
}
