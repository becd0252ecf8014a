//! A part of the scene's GPU state beside its geometry and textures — the environment light's
//! maps, the shadow stores, the blinn-phong model's other lights — as the frames see it: what
//! it binds in the scene's set 1, the buffers shaders bind from a frame's table, the images
//! passes declare (`sync`), the frame uniforms it owns, each by name, and its rows of the
//! run's table. The renderer holds the parts and asks each in turn: the shadow stores (which
//! the shadow passes share) and the parts the features make (a feature's `part`, listed in the
//! assembly's `FEATURES`), so a new part is its module and its feature's line. A part's module reaches its part again through
//! `PartHost` (the environment's view).

use crate::descriptors::Resource;
use crate::error::RenderError;
use crate::report::FrameStats;
use crate::sync::{BufferName, ImageName};
use ml_cpu::gpu_types::FrameUniforms;
use ml_cpu::scene::Scene;
use ml_vk::{vk, Context};
use std::any::Any;

pub trait ScenePart {
    /// What it binds in the scene's set 1 under `name` (common/textures.glsl and the
    /// features' set-1 headers).
    fn resource(&self, name: &str) -> Option<Resource>;

    /// Its buffers shaders bind from a frame's table, under their blocks' names.
    fn named_buffers(&self) -> Vec<(BufferName, vk::Buffer)> {
        Vec::new()
    }

    /// Its images that passes declare, under their names (`sync`).
    fn named_image(&self, _name: ImageName) -> Option<(vk::Image, vk::ImageAspectFlags)> {
        None
    }

    /// Fill the frame's uniforms it owns.
    fn frame_uniforms(&self, _uniforms: &mut FrameUniforms) {}

    /// Its figures for the run's table (`stats.set_feature`), with what the last frame counted.
    fn report(&self, _counts: &FrameCounts, _stats: &mut FrameStats) {}
}

/// A scene part the renderer owns: made for its scene by a `MakePart`, released with it.
pub trait OwnedPart: ScenePart + Any {
    fn destroy(&mut self, _ctx: &Context) {}
}

/// How a part is made for a scene (a feature's `part`, `feature::Feature`).
pub type MakePart = fn(&Context, &Scene) -> Result<Box<dyn OwnedPart>, RenderError>;

/// The parts the features made, in the assembly's order.
#[derive(Default)]
pub struct OwnedParts(pub Vec<Box<dyn OwnedPart>>);

impl OwnedParts {
    /// Each of `makers` for `scene`; where one fails, those made before it are released.
    pub fn make(ctx: &Context, scene: &Scene, makers: impl IntoIterator<Item = MakePart>) -> Result<OwnedParts, RenderError> {
        let mut parts = OwnedParts::default();
        for make in makers {
            let made = make(ctx, scene);
            let part = ml_vk::release_on_error(ctx, made, &mut [&mut parts])?;
            parts.0.push(part);
        }
        Ok(parts)
    }

    /// The part of type `T`, if one was made.
    pub fn get_mut<T: OwnedPart>(&mut self) -> Option<&mut T> {
        self.0.iter_mut().find_map(|p| (p.as_mut() as &mut dyn Any).downcast_mut::<T>())
    }
}

impl ml_vk::Release for OwnedParts {
    fn release(&mut self, ctx: &Context) {
        for p in &mut self.0 {
            p.destroy(ctx);
        }
        self.0.clear();
    }
}

/// What a scene part's module may reach of the renderer that holds its part, to change it
/// and the scene together (the environment's view): its fields are the crate's own.
pub struct PartAccess<'r> {
    pub(crate) ctx: &'r Context,
    pub(crate) scene: &'r mut Scene,
    pub(crate) parts: &'r mut OwnedParts,
}

/// The renderer, as the scene parts' modules see it (they cannot name it: it assembles them).
pub trait PartHost {
    fn part_access(&mut self) -> PartAccess<'_>;
}

/// `first` (the shadow stores) and then the owned parts: every part, as the frames ask them
/// (each frame, for its uniforms and images: no list is built).
pub fn all<'s>(first: &'s dyn ScenePart, owned: &'s OwnedParts) -> impl Iterator<Item = &'s dyn ScenePart> {
    std::iter::once(first).chain(owned.0.iter().map(|p| p.as_ref() as &dyn ScenePart))
}

/// What the last frame counted on the GPU that a part reports with its own figures.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameCounts {
    /// The shadow rays the compute lighting traced from the opaque surfaces (None where they
    /// are not counted: without `--light-stats`).
    pub rays_traced: Option<u64>,
}

/// The first of `parts` that binds `name` in set 1.
pub fn resource<'s>(mut parts: impl Iterator<Item = &'s dyn ScenePart>, name: &str) -> Option<Resource> {
    parts.find_map(|p| p.resource(name))
}

/// The first of `parts` that has the image `name`.
pub fn named_image<'s>(mut parts: impl Iterator<Item = &'s dyn ScenePart>, name: ImageName) -> Option<(vk::Image, vk::ImageAspectFlags)> {
    parts.find_map(|p| p.named_image(name))
}
