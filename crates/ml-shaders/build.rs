//! Compiles every shader under `<workspace>/shaders` (`*.vert`, `*.frag`, `*.comp`) to SPIR-V
//! with glslang (a crate: no system package, no Vulkan SDK). `#include "x.glsl"` is resolved
//! from the same folder.
//!
//! Each shader is also reflected (spirq): its descriptor bindings — set, binding, kind, count
//! and name — become data next to its SPIR-V, so the binding numbers are written once, in the
//! GLSL, and Rust derives set layouts, pool sizes and descriptor writes from them.

use glslang::{
    include::{IncludeHandler, IncludeResult, IncludeType},
    Compiler, CompilerOptions, ShaderInput, ShaderSource, ShaderStage, SpirvVersion, Target, VulkanVersion,
};
use std::path::{Path, PathBuf};

struct FolderIncludes(PathBuf);

impl IncludeHandler for FolderIncludes {
    fn include(&mut self, _ty: IncludeType, header_name: &str, _includer_name: &str, _include_depth: usize) -> Option<IncludeResult> {
        let path = self.0.join(header_name);
        let data = std::fs::read_to_string(&path).ok()?;
        Some(IncludeResult { name: path.display().to_string(), data })
    }
}

fn stage_of(path: &Path) -> Option<ShaderStage> {
    match path.extension()?.to_str()? {
        "vert" => Some(ShaderStage::Vertex),
        "frag" => Some(ShaderStage::Fragment),
        "comp" => Some(ShaderStage::Compute),
        _ => None,
    }
}

/// The `DescriptorKind` variant of a reflected descriptor type.
fn kind_of(ty: &spirq::ty::DescriptorType) -> &'static str {
    use spirq::ty::DescriptorType as D;
    match ty {
        D::Sampler() => "Sampler",
        D::CombinedImageSampler() => "CombinedImageSampler",
        D::SampledImage() => "SampledImage",
        D::StorageImage(_) => "StorageImage",
        D::UniformBuffer() => "UniformBuffer",
        D::StorageBuffer(_) => "StorageBuffer",
        D::InputAttachment(_) => "InputAttachment",
        other => panic!("descriptor type {other:?} is not used by manylights"),
    }
}

/// `Binding { .. }` literals of every descriptor the module declares (used or not: a layout
/// must name what a specialization may switch on), sorted by set and binding. A block's name
/// is its block type's (`LightBuffer`), an image's its variable's (`depth_image`).
fn reflect_bindings(file: &str, words: &[u32]) -> String {
    let entries =
        spirq::ReflectConfig::new().spv(words.to_vec()).ref_all_rscs(true).reflect().unwrap_or_else(|e| panic!("{file}: reflection: {e}"));
    let mut found = std::collections::BTreeMap::new();
    for entry in entries {
        for var in entry.vars {
            if let spirq::var::Variable::Descriptor { name, desc_bind, desc_ty, ty, nbind } = var {
                let block = match &ty {
                    spirq::ty::Type::Struct(s) => s.name().map(str::to_owned),
                    _ => None,
                };
                let name = block.or(name).unwrap_or_default();
                found.insert((desc_bind.set(), desc_bind.bind()), (kind_of(&desc_ty), nbind, name));
            }
        }
    }
    found
        .into_iter()
        .map(|((set, binding), (kind, count, name))| {
            format!("Binding {{ set: {set}, binding: {binding}, kind: DescriptorKind::{kind}, count: {count}, name: {name:?} }}, ")
        })
        .collect()
}

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let shader_dir = manifest.join("../../shaders").canonicalize().expect("shaders/ folder");
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    println!("cargo:rerun-if-changed={}", shader_dir.display());

    let compiler = Compiler::acquire().expect("glslang compiler");
    let options = CompilerOptions {
        target: Target::Vulkan { version: VulkanVersion::Vulkan1_2, spirv_version: SpirvVersion::SPIRV1_5 },
        ..CompilerOptions::default()
    };
    let mut entries: Vec<PathBuf> = std::fs::read_dir(&shader_dir).expect("read shaders/").map(|e| e.unwrap().path()).collect();
    entries.sort();
    let mut index = String::new();
    let mut all = String::from("/// Every compiled shader, for reflection tests.\npub const ALL: &[Shader] = &[\n");
    for path in entries {
        println!("cargo:rerun-if-changed={}", path.display());
        let Some(stage) = stage_of(&path) else { continue };
        let text = std::fs::read_to_string(&path).unwrap();
        let source = ShaderSource::from(text);
        let mut includes = FolderIncludes(shader_dir.clone());
        let input = ShaderInput::new(&source, stage, &options, None::<&[(&str, Option<&str>)]>, Some(&mut includes))
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let shader = glslang::Shader::new(compiler, input).parse().unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let words = shader.compile().unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let file_name = path.file_name().unwrap().to_str().unwrap().to_owned();
        let spv_name = format!("{file_name}.spv");
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        std::fs::write(out_dir.join(&spv_name), bytes).unwrap();
        let const_name = file_name.replace('.', "_").to_uppercase();
        let bindings = reflect_bindings(&file_name, &words);
        index.push_str(&format!(
            "/// `shaders/{file_name}`.\npub const {const_name}: Shader = Shader {{ file: {file_name:?}, spirv: include_bytes!(concat!(env!(\"OUT_DIR\"), \"/{spv_name}\")), bindings: &[{bindings}] }};\n"
        ));
        all.push_str(&format!("    {const_name},\n"));
    }
    index.push_str(&all);
    index.push_str("];\n");
    std::fs::write(out_dir.join("shaders.rs"), index).unwrap();
}
