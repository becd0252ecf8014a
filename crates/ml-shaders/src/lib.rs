//! The GLSL shaders under `shaders/`, compiled to SPIR-V by this crate's build script, each
//! with what SPIR-V reflection reports of it. Each `shaders/folder/name.stage` becomes the
//! constant `NAME_STAGE` (the folder is left out, so file names are unique across folders:
//! the build checks it); `ALL` lists them all.
//!
//! The GLSL is the one source of the numbers Rust and the shaders share:
//! - binding numbers: Rust builds set layouts and descriptor pools from `Shader::bindings` and
//!   writes descriptors by the names the shaders give them;
//! - specialization constants: Rust sets them by the names the GLSL declares
//!   (`layout(constant_id = N) const bool NAME`), each resolved to its id through
//!   `Shader::spec_id` when a pipeline is made, so an id is written once, in the GLSL (it
//!   need only be unique within a module, which the build checks);
//! - work-group sizes: a dispatch divides its invocations by `Shader::workgroup_size`, the
//!   shader's `local_size_x/y/z`;
//! - the debug views' codes (`debug_view`) and the other numbers `common.glsl` defines for
//!   Rust to write (`common`).
//!
//! # Folders and includes
//!
//! Shaders lie in folders by the feature of ml-render that runs them: `common/` (headers
//! several features share: the structs Rust mirrors, bindings, the light loop, BRDFs,
//! surfaces, alpha masks), `shading/`, `visibility/`, `shadows/`, `clusters/`, `exposure/` and
//! `probe/`. A header that one feature owns and another borrows stays with its owner (the
//! raster rules in `visibility/`, which the compute shadow raster includes too).
//!
//! An `#include` names its header by its path under `shaders/`, from any folder:
//! `#include "common/common.glsl"`, also within one folder. One rule with no search order:
//! each include line says where its header lies, and moving a header breaks the build rather
//! than finding another file of the same name.

/// A compiled shader module.
#[derive(Clone, Copy, Debug)]
pub struct Shader {
    /// Path under `shaders/` (`shading/forward.frag`).
    pub file: &'static str,
    pub spirv: &'static [u8],
    /// Every descriptor the module declares, sorted by set and binding.
    pub bindings: &'static [Binding],
    /// Every specialization constant the module declares, its headers' included, sorted by id
    /// (glslang keeps those no code reads too).
    pub spec_constants: &'static [SpecConstant],
    /// `local_size_x/y/z` of a compute shader; [1, 1, 1] for the other stages.
    pub workgroup_size: [u32; 3],
}

/// One descriptor binding of a shader.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Binding {
    pub set: u32,
    pub binding: u32,
    pub kind: DescriptorKind,
    /// Array length (1 for a single descriptor).
    pub count: u32,
    /// A block's type name (`LightBuffer`), else the variable's (`depth_image`).
    pub name: &'static str,
}

/// The Vulkan descriptor type of a binding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum DescriptorKind {
    Sampler,
    CombinedImageSampler,
    SampledImage,
    StorageImage,
    UniformBuffer,
    StorageBuffer,
    InputAttachment,
}

/// One specialization constant of a shader: `layout(constant_id = id) const ... name`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SpecConstant {
    pub name: &'static str,
    pub id: u32,
}

impl Shader {
    /// The bindings of descriptor set `set`.
    pub fn set(&self, set: u32) -> impl Iterator<Item = &'static Binding> {
        self.bindings.iter().filter(move |b| b.set == set)
    }

    /// The `constant_id` of the specialization constant `name`, if the module declares it.
    pub fn spec_id(&self, name: &str) -> Option<u32> {
        self.spec_constants.iter().find(|c| c.name == name).map(|c| c.id)
    }

    /// The work groups that cover `invocations` (one per item along each axis): each axis
    /// divided by the work-group size, rounded up.
    pub fn groups(&self, invocations: [u32; 3]) -> [u32; 3] {
        std::array::from_fn(|i| invocations[i].div_ceil(self.workgroup_size[i]))
    }
}

/// The codes of the debug views as the shaders compare `FrameUniforms::viewport.z`
/// against them: `#define DEBUG_VIEW_NAME Nu` in `shaders/common/common.glsl` becomes `NAME`.
pub mod debug_view {
    include!(concat!(env!("OUT_DIR"), "/debug_view.rs"));
}

/// The other unsigned numbers `shaders/common/common.glsl` defines (`#define NAME Nu`), named
/// as there: values Rust writes into buffers the shaders read.
pub mod common {
    include!(concat!(env!("OUT_DIR"), "/common_defines.rs"));
}

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));

#[cfg(test)]
mod tests;
#[cfg(test)]
mod uniform_branches;
