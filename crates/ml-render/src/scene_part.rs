//! A part of the scene's GPU state beside its geometry and textures — the environment light's
//! maps, the shadow stores, the blinn-phong model's other lights — as the frames see it: what
//! it binds in the scene's set 1, the buffers shaders bind from a frame's table, the images
//! passes declare (`sync`), the frame uniforms it owns, each by name, and its rows of the
//! run's table. The renderer holds the parts and asks each in turn, so a new one is its module
//! and its line in the renderer's list (`scene_parts` in renderer.rs).

use crate::descriptors::Resource;
use crate::report::FrameStats;
use ml_cpu::gpu_types::FrameUniforms;
use ml_vk::vk;

pub trait ScenePart {
    /// What it binds in the scene's set 1 under `name` (common/textures.glsl and the
    /// features' set-1 headers).
    fn resource(&self, name: &str) -> Option<Resource>;

    /// Its buffers shaders bind from a frame's table, under their blocks' names.
    fn named_buffers(&self) -> Vec<(&'static str, vk::Buffer)> {
        Vec::new()
    }

    /// Its images that passes declare, under their names (`sync`).
    fn named_image(&self, _name: &str) -> Option<(vk::Image, vk::ImageAspectFlags)> {
        None
    }

    /// Fill the frame's uniforms it owns.
    fn frame_uniforms(&self, _uniforms: &mut FrameUniforms) {}

    /// Its figures for the run's table (`stats.set_feature`), with what the last frame counted.
    fn report(&self, _counts: &FrameCounts, _stats: &mut FrameStats) {}
}

/// What the last frame counted on the GPU that a part reports with its own figures.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameCounts {
    /// The shadow rays the compute lighting traced from the opaque surfaces (None where they
    /// are not counted: without `--light-stats`).
    pub rays_traced: Option<u64>,
}

/// The first of `parts` that binds `name` in set 1.
pub fn resource(parts: &[&dyn ScenePart], name: &str) -> Option<Resource> {
    parts.iter().find_map(|p| p.resource(name))
}

/// The first of `parts` that has the image `name`.
pub fn named_image(parts: &[&dyn ScenePart], name: &str) -> Option<(vk::Image, vk::ImageAspectFlags)> {
    parts.iter().find_map(|p| p.named_image(name))
}
