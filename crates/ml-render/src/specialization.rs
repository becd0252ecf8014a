//! Specialization constants by the names the GLSL gives them: a pass says
//! `("MODEL_PBR", 1)`, and the ids (`layout(constant_id = 11)`) come from the shaders'
//! reflection (ml-shaders `Shader::spec_constants`) when the pipeline is made, so an id is
//! written once, in the GLSL and nowhere in Rust.
//!
//! One list of constants serves every stage of a pipeline: each stage gets those it declares.
//! A stage may lack one (a vertex stage declares no shading model), but a name that no stage
//! of the pipeline declares is a mistake — a renamed or misspelt constant, or one set on a
//! pipeline whose shaders never read it — and an error, not a constant silently left at its
//! default.

use ml_shaders::Shader;
use ml_vk::{shader, vk, Context, VkError};

/// A constant that none of a pipeline's stages declares.
#[derive(Debug, PartialEq, thiserror::Error)]
#[error("specialization constant '{name}' is declared by none of {stages:?}")]
pub struct UnknownConstant {
    pub name: String,
    pub stages: Vec<&'static str>,
}

/// A specialization constant by name, and its value.
pub type Constant = (&'static str, u32);

/// Per stage of one pipeline, the (id, value) pairs of the `constants` (name, value) that it
/// declares; a name none declares is an error.
pub fn resolve<const N: usize>(stages: [&Shader; N], constants: &[(&str, u32)]) -> Result<[Vec<(u32, u32)>; N], UnknownConstant> {
    if let Some(&(name, _)) = constants.iter().find(|(name, _)| stages.iter().all(|s| s.spec_id(name).is_none())) {
        return Err(UnknownConstant { name: name.to_owned(), stages: stages.iter().map(|s| s.file).collect() });
    }
    Ok(stages.map(|s| constants.iter().filter_map(|&(name, value)| Some((s.spec_id(name)?, value))).collect()))
}

/// Specialization constants by name as the features contribute them, each from its own
/// module (a value, so the settings holding them stay `Copy` and comparable).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Constants {
    entries: [(&'static str, u32); Constants::CAPACITY],
    len: usize,
}

impl Constants {
    /// More than every feature's constants of one kind of pipeline together.
    pub const CAPACITY: usize = 24;

    /// The features' `groups` one after another (more than `CAPACITY` is a bug: raise it).
    pub fn of(groups: &[&[(&'static str, u32)]]) -> Constants {
        let mut c = Constants { entries: [("", 0); Constants::CAPACITY], len: 0 };
        for &(name, value) in groups.iter().copied().flatten() {
            assert!(c.len < Constants::CAPACITY, "more than {} specialization constants", Constants::CAPACITY);
            debug_assert!(c.get(name).is_none(), "{name} contributed twice");
            c.entries[c.len] = (name, value);
            c.len += 1;
        }
        c
    }

    pub fn as_slice(&self) -> &[(&'static str, u32)] {
        &self.entries[..self.len]
    }

    /// The value of the constant `name`, where a feature contributed it.
    pub fn get(&self, name: &str) -> Option<u32> {
        self.as_slice().iter().find(|(n, _)| *n == name).map(|&(_, v)| v)
    }
}

/// Reported as the other shader-interface mismatches are (descriptors.rs).
impl From<UnknownConstant> for VkError {
    fn from(e: UnknownConstant) -> VkError {
        VkError::Interface(e.to_string())
    }
}

/// The compute pipeline of `shader` with `layout`, its `constants` set by name.
pub fn compute_pipeline(
    ctx: &Context,
    shader: &Shader,
    layout: vk::PipelineLayout,
    constants: &[(&str, u32)],
) -> Result<vk::Pipeline, VkError> {
    let [ids] = resolve([shader], constants)?;
    shader::compute_pipeline(ctx, shader.file, shader.spirv, layout, &ids)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ml_shaders::SpecConstant;

    const VERT: Shader = Shader { file: "a.vert", spirv: &[], bindings: &[], spec_constants: &[], workgroup_size: [1; 3] };
    const FRAG: Shader = Shader {
        file: "a.frag",
        spirv: &[],
        bindings: &[],
        spec_constants: &[SpecConstant { name: "MODEL_PBR", id: 11 }, SpecConstant { name: "MASKED_DRAW", id: 16 }],
        workgroup_size: [1; 3],
    };

    #[test]
    fn names_become_each_stages_ids() {
        let [v, f] = resolve([&VERT, &FRAG], &[("MASKED_DRAW", 1), ("MODEL_PBR", 0)]).expect("both declared");
        assert!(v.is_empty());
        assert_eq!(f, vec![(16, 1), (11, 0)]);
    }

    #[test]
    fn a_name_no_stage_declares_is_an_error() {
        let e = resolve([&VERT, &FRAG], &[("MODEL_PBR", 1), ("MODEL_PRB", 1)]).unwrap_err();
        assert_eq!(e, UnknownConstant { name: "MODEL_PRB".into(), stages: vec!["a.vert", "a.frag"] });
        assert!(resolve([&VERT], &[("MODEL_PBR", 1)]).is_err());
    }

    #[test]
    fn constants_keep_the_features_order_and_find_by_name() {
        let c = Constants::of(&[&[("MODEL_PBR", 1), ("OBJECT_TEXTURES", 0)], &[], &[("ENVIRONMENT", 1)]]);
        assert_eq!(c.as_slice(), &[("MODEL_PBR", 1), ("OBJECT_TEXTURES", 0), ("ENVIRONMENT", 1)]);
        assert_eq!((c.get("ENVIRONMENT"), c.get("OBJECT_TEXTURES"), c.get("SHADOW_RAYS")), (Some(1), Some(0), None));
    }

    #[test]
    fn ids_come_from_the_glsl() {
        // The ids come from the GLSL (common/shading_model.glsl: constant_id 10 and 11).
        let [f] = resolve([&ml_shaders::FORWARD_FRAG], &[("MODEL_BLINN_PHONG", 1), ("MODEL_PBR", 0)]).unwrap();
        assert_eq!(f, vec![(10, 1), (11, 0)]);
    }
}
