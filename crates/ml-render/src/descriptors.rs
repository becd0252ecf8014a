//! Descriptor set layouts, pools and writes derived from the shaders' reflected bindings
//! (ml-shaders): binding numbers live only in the GLSL. A pass names the shaders of a pipeline
//! and a set; the layout is the union of what those stages declare, a pool is sized from the
//! layouts it serves, and a set is written by the names the shaders give their bindings.

use ml_shaders::{Binding, DescriptorKind, Shader};
use ml_vk::{vk, Context, VkError, VkResultExt};

/// A set layout and the bindings it was made from.
pub struct SetLayout {
    pub raw: vk::DescriptorSetLayout,
    pub bindings: Vec<(Binding, vk::ShaderStageFlags)>,
}

/// What a descriptor of a set points at.
#[derive(Clone, Copy)]
pub enum Resource {
    /// A whole buffer.
    Buffer(vk::Buffer),
    /// An image (view, layout and, for sampled kinds, sampler).
    Image(vk::DescriptorImageInfo),
}

/// Why the stages of one pipeline cannot share a set layout.
#[derive(Debug, PartialEq, thiserror::Error)]
#[error(
    "set {set} binding {binding}: {first} declares {first_kind:?} '{first_name}' but {second} declares {second_kind:?} '{second_name}'"
)]
pub struct LayoutMismatch {
    pub set: u32,
    pub binding: u32,
    pub first: &'static str,
    pub first_kind: DescriptorKind,
    pub first_name: &'static str,
    pub second: &'static str,
    pub second_kind: DescriptorKind,
    pub second_name: &'static str,
}

/// The bindings of set `set` as the union of `stages`' declarations, each with the stages
/// that declare it; two stages declaring one binding differently (kind, count or name) is
/// an error.
pub fn merge(stages: &[(&Shader, vk::ShaderStageFlags)], set: u32) -> Result<Vec<(Binding, vk::ShaderStageFlags)>, LayoutMismatch> {
    let mut merged: Vec<(Binding, vk::ShaderStageFlags, &'static str)> = Vec::new();
    for (shader, stage) in stages {
        for b in shader.set(set) {
            match merged.iter_mut().find(|(m, _, _)| m.binding == b.binding) {
                Some((m, stages, _)) if m == b => *stages |= *stage,
                Some((m, _, first)) => {
                    return Err(LayoutMismatch {
                        set,
                        binding: b.binding,
                        first,
                        first_kind: m.kind,
                        first_name: m.name,
                        second: shader.file,
                        second_kind: b.kind,
                        second_name: b.name,
                    })
                }
                None => merged.push((*b, *stage, shader.file)),
            }
        }
    }
    merged.sort_by_key(|(b, _, _)| b.binding);
    Ok(merged.into_iter().map(|(b, s, _)| (b, s)).collect())
}

pub fn vk_type(kind: DescriptorKind) -> vk::DescriptorType {
    match kind {
        DescriptorKind::Sampler => vk::DescriptorType::SAMPLER,
        DescriptorKind::CombinedImageSampler => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        DescriptorKind::SampledImage => vk::DescriptorType::SAMPLED_IMAGE,
        DescriptorKind::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
        DescriptorKind::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
        DescriptorKind::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
        DescriptorKind::InputAttachment => vk::DescriptorType::INPUT_ATTACHMENT,
    }
}

impl SetLayout {
    /// Set `set` of the pipeline whose stages are `stages`.
    pub fn new(ctx: &Context, stages: &[(&Shader, vk::ShaderStageFlags)], set: u32) -> Result<SetLayout, VkError> {
        let bindings = merge(stages, set).map_err(|e| VkError::Interface(e.to_string()))?;
        let raw_bindings: Vec<vk::DescriptorSetLayoutBinding> = bindings
            .iter()
            .map(|(b, stages)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b.binding)
                    .descriptor_type(vk_type(b.kind))
                    .descriptor_count(b.count)
                    .stage_flags(*stages)
            })
            .collect();
        Ok(SetLayout { raw: ml_vk::shader::set_layout_of(ctx, &raw_bindings)?, bindings })
    }

    pub fn null() -> SetLayout {
        SetLayout { raw: vk::DescriptorSetLayout::null(), bindings: Vec::new() }
    }

    /// Point every binding of `set` (of this layout) at what `lookup` says for its name; a
    /// binding `lookup` does not know is an error (a shader declares what Rust never provides).
    pub fn write(&self, ctx: &Context, set: vk::DescriptorSet, lookup: &dyn Fn(&str) -> Option<Resource>) -> Result<(), VkError> {
        for (b, _) in &self.bindings {
            let resource = lookup(b.name)
                .ok_or_else(|| VkError::Interface(format!("binding '{}' (binding {}) has nothing to point at", b.name, b.binding)))?;
            let ty = vk_type(b.kind);
            match resource {
                Resource::Buffer(buffer) => ml_vk::descriptors::write_buffer(ctx, set, b.binding, ty, buffer),
                Resource::Image(image) => ml_vk::descriptors::write_image(ctx, set, b.binding, ty, image),
            }
        }
        Ok(())
    }

    /// Let go of the layout (the context's: shared, destroyed with it).
    pub fn destroy(&mut self, _ctx: &Context) {
        self.raw = vk::DescriptorSetLayout::null();
    }
}

/// Pool sizes for `copies` sets of each layout, summed from their bindings.
pub fn pool_sizes(layouts: &[(&SetLayout, u32)]) -> Vec<vk::DescriptorPoolSize> {
    let mut sizes: Vec<vk::DescriptorPoolSize> = Vec::new();
    for (layout, copies) in layouts {
        for (b, _) in &layout.bindings {
            let ty = vk_type(b.kind);
            match sizes.iter_mut().find(|s| s.ty == ty) {
                Some(s) => s.descriptor_count += b.count * copies,
                None => sizes.push(vk::DescriptorPoolSize { ty, descriptor_count: b.count * copies }),
            }
        }
    }
    sizes
}

/// A pool for `copies` sets of each layout (made again with `reset` when they are remade).
pub fn pool(ctx: &Context, layouts: &[(&SetLayout, u32)]) -> Result<vk::DescriptorPool, VkError> {
    let sizes = pool_sizes(layouts);
    let max_sets = layouts.iter().map(|(_, n)| n).sum::<u32>().max(1);
    let info = vk::DescriptorPoolCreateInfo::default().max_sets(max_sets).pool_sizes(&sizes);
    // SAFETY: valid device and create info.
    unsafe { ctx.device.create_descriptor_pool(&info, None) }.ctx("vkCreateDescriptorPool")
}

/// One set of a layout per frame slot, from a pool of their own, each written by name.
pub struct FrameSets {
    pub layout: SetLayout,
    pool: vk::DescriptorPool,
    pub sets: Vec<vk::DescriptorSet>,
}

impl FrameSets {
    /// None yet (a pass under construction).
    pub fn empty() -> FrameSets {
        FrameSets { layout: SetLayout::null(), pool: vk::DescriptorPool::null(), sets: Vec::new() }
    }

    /// `slots` sets of set `set` of the pipeline whose stages are `stages`.
    pub fn new(ctx: &Context, stages: &[(&Shader, vk::ShaderStageFlags)], set: u32, slots: usize) -> Result<FrameSets, VkError> {
        let mut f = FrameSets { layout: SetLayout::new(ctx, stages, set)?, pool: vk::DescriptorPool::null(), sets: Vec::new() };
        let made = pool(ctx, &[(&f.layout, slots as u32)]).and_then(|p| {
            f.pool = p;
            (0..slots).map(|_| ml_vk::descriptors::allocate_set(ctx, p, f.layout.raw)).collect::<Result<Vec<_>, _>>()
        });
        match made {
            Ok(sets) => {
                f.sets = sets;
                Ok(f)
            }
            Err(e) => {
                f.destroy(ctx);
                Err(e)
            }
        }
    }

    /// Point slot `slot`'s set at what `lookup` names (only while the slot is not in flight).
    pub fn write(&self, ctx: &Context, slot: usize, lookup: &dyn Fn(&str) -> Option<Resource>) -> Result<(), VkError> {
        self.layout.write(ctx, self.sets[slot], lookup)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: no pending work uses the pool's sets; a null handle is ignored.
        unsafe { ctx.device.destroy_descriptor_pool(self.pool, None) };
        self.pool = vk::DescriptorPool::null();
        self.sets.clear();
        self.layout.destroy(ctx);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FRAME: Binding = Binding { set: 0, binding: 0, kind: DescriptorKind::UniformBuffer, count: 1, name: "FrameBlock" };
    const LIGHTS: Binding = Binding { set: 0, binding: 1, kind: DescriptorKind::StorageBuffer, count: 1, name: "LightBuffer" };
    const IMAGE: Binding = Binding { set: 0, binding: 1, kind: DescriptorKind::CombinedImageSampler, count: 1, name: "depth_image" };
    const VERT: Shader = Shader { file: "a.vert", spirv: &[], bindings: &[FRAME], spec_constants: &[], workgroup_size: [1; 3] };
    const FRAG: Shader = Shader { file: "a.frag", spirv: &[], bindings: &[FRAME, LIGHTS], spec_constants: &[], workgroup_size: [1; 3] };
    const OTHER: Shader = Shader { file: "b.frag", spirv: &[], bindings: &[FRAME, IMAGE], spec_constants: &[], workgroup_size: [1; 3] };

    #[test]
    fn stages_share_a_binding_and_add_theirs() {
        let (v, f) = (vk::ShaderStageFlags::VERTEX, vk::ShaderStageFlags::FRAGMENT);
        let merged = merge(&[(&VERT, v), (&FRAG, f)], 0).expect("compatible");
        assert_eq!(merged, vec![(FRAME, v | f), (LIGHTS, f)]);
        assert!(merge(&[(&VERT, v)], 1).expect("empty set").is_empty());
    }

    #[test]
    fn a_binding_declared_two_ways_is_refused() {
        let (v, f) = (vk::ShaderStageFlags::VERTEX, vk::ShaderStageFlags::FRAGMENT);
        let e = merge(&[(&FRAG, v), (&OTHER, f)], 0).expect_err("binding 1 is a buffer in one, an image in the other");
        assert_eq!((e.binding, e.first, e.second), (1, "a.frag", "b.frag"));
    }

    #[test]
    fn pools_are_sized_from_the_layouts() {
        let layout = SetLayout {
            raw: vk::DescriptorSetLayout::null(),
            bindings: vec![(FRAME, vk::ShaderStageFlags::ALL), (LIGHTS, vk::ShaderStageFlags::ALL)],
        };
        let sizes = pool_sizes(&[(&layout, 2)]);
        let count = |ty| sizes.iter().find(|s| s.ty == ty).map(|s| s.descriptor_count);
        assert_eq!(count(vk::DescriptorType::UNIFORM_BUFFER), Some(2));
        assert_eq!(count(vk::DescriptorType::STORAGE_BUFFER), Some(2));
    }
}
