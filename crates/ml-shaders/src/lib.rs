//! The GLSL shaders under `shaders/`, compiled to SPIR-V by this crate's build script, each
//! with its descriptor bindings as SPIR-V reflection reports them. Each `shaders/name.stage`
//! becomes the constant `NAME_STAGE`; `ALL` lists them all.
//!
//! Binding numbers are written once, in the GLSL: Rust builds set layouts and descriptor
//! pools from `Shader::bindings` and writes descriptors by the names the shaders give them.

/// A compiled shader module.
#[derive(Clone, Copy, Debug)]
pub struct Shader {
    /// File name under `shaders/` (`forward.frag`).
    pub file: &'static str,
    pub spirv: &'static [u8],
    /// Every descriptor the module declares, sorted by set and binding.
    pub bindings: &'static [Binding],
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

impl Shader {
    /// The bindings of descriptor set `set`.
    pub fn set(&self, set: u32) -> impl Iterator<Item = &'static Binding> {
        self.bindings.iter().filter(move |b| b.set == set)
    }
}

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
