//! Compiles every shader under `<workspace>/shaders` (`*.vert`, `*.frag`, `*.comp`, in the
//! feature folders) to SPIR-V with glslang (a crate: no system package, no Vulkan SDK).
//! `#include "folder/x.glsl"` names a header by its path under `shaders/`, wherever the
//! including file lies: one rule, and each include line says where its header is.
//!
//! Each shader is also reflected (spirq), and what the GLSL says becomes data next to its
//! SPIR-V, so that Rust never repeats a number the GLSL holds:
//! - its descriptor bindings — set, binding, kind, count and name — from which Rust derives
//!   set layouts, pool sizes and descriptor writes;
//! - its specialization constants — name and `constant_id` — by which Rust names the
//!   constants it sets, at pipeline creation;
//! - a compute shader's work-group size (`local_size_x/y/z`), by which Rust divides the
//!   invocations it dispatches.
//!
//! The `#define DEBUG_VIEW_* Nu` lines of `common/common.glsl` become `debug_view::*`, and its
//! other `#define NAME Nu` lines `common::NAME`: the values the shaders compare against, for
//! Rust to write.

use glslang::{
    include::{IncludeHandler, IncludeResult, IncludeType},
    Compiler, CompilerOptions, ShaderInput, ShaderSource, ShaderStage, SpirvVersion, Target, VulkanVersion,
};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Resolves `#include "folder/x.glsl"` against the shaders' root folder.
struct RootIncludes(PathBuf);

impl IncludeHandler for RootIncludes {
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

/// Every file under `dir`, folders followed, sorted (so the generated code is stable).
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(files_under(&path));
        } else {
            out.push(path);
        }
    }
    out.sort();
    out
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

/// What reflection reports of one module, as the Rust literals of `Shader`'s fields.
struct Reflected {
    bindings: String,
    spec_constants: String,
    workgroup_size: [u32; 3],
}

/// Reflect `words` (the SPIR-V of `file`, a `stage` shader).
///
/// Bindings: every descriptor the module declares (used or not: a layout must name what a
/// specialization may switch on), sorted by set and binding. A block's name is its block
/// type's (`LightBuffer`), an image's its variable's (`depth_image`).
///
/// Specialization constants: every one the module declares, its headers' included (glslang
/// keeps those no code reads too), sorted by id; each must be named, and ids and names must
/// not repeat.
///
/// Work-group size: the LocalSize execution mode of a compute shader, [1, 1, 1] for the
/// other stages.
fn reflect(file: &str, stage: ShaderStage, words: &[u32]) -> Reflected {
    let entries =
        spirq::ReflectConfig::new().spv(words.to_vec()).ref_all_rscs(true).reflect().unwrap_or_else(|e| panic!("{file}: reflection: {e}"));
    assert_eq!(entries.len(), 1, "{file}: one entry point expected");
    let entry = &entries[0];
    let mut bindings = BTreeMap::new();
    let mut spec = BTreeMap::new();
    for var in &entry.vars {
        match var {
            spirq::var::Variable::Descriptor { name, desc_bind, desc_ty, ty, nbind } => {
                let block = match ty {
                    spirq::ty::Type::Struct(s) => s.name().map(str::to_owned),
                    _ => None,
                };
                let name = block.or(name.clone()).unwrap_or_default();
                bindings.insert((desc_bind.set(), desc_bind.bind()), (kind_of(desc_ty), *nbind, name));
            }
            spirq::var::Variable::SpecConstant { name, spec_id, .. } => {
                let name = name.clone().unwrap_or_else(|| panic!("{file}: specialization constant {spec_id} has no name"));
                if let Some(other) = spec.insert(*spec_id, name.clone()) {
                    panic!("{file}: constant_id {spec_id} names both {other} and {name}");
                }
            }
            _ => {}
        }
    }
    let names: std::collections::BTreeSet<&String> = spec.values().collect();
    assert_eq!(names.len(), spec.len(), "{file}: two specialization constants of one name");
    let mut workgroup_size = [1; 3];
    let mut found = false;
    for mode in &entry.exec_modes {
        match mode.exec_mode {
            spirq::spirv::ExecutionMode::LocalSize => {
                for (axis, operand) in workgroup_size.iter_mut().zip(&mode.operands) {
                    *axis = match operand.value {
                        spirq::constant::ConstantValue::U32(v) => v,
                        ref other => panic!("{file}: local size {other:?}"),
                    };
                }
                found = true;
            }
            spirq::spirv::ExecutionMode::LocalSizeId => panic!("{file}: local_size_*_id is not supported (Rust divides by a fixed size)"),
            _ => {}
        }
    }
    assert_eq!(found, matches!(stage, ShaderStage::Compute), "{file}: a compute shader, and only one, has a local size");
    Reflected {
        bindings: bindings
            .into_iter()
            .map(|((set, binding), (kind, count, name))| {
                format!("Binding {{ set: {set}, binding: {binding}, kind: DescriptorKind::{kind}, count: {count}, name: {name:?} }}, ")
            })
            .collect(),
        spec_constants: spec.into_iter().map(|(id, name)| format!("SpecConstant {{ name: {name:?}, id: {id} }}, ")).collect(),
        workgroup_size,
    }
}

/// `(NAME, number)` of each `#define NAME <decimal or 0x hex>u` line of `text`, the number
/// spelt as in the GLSL without its `u`: the unsigned numbers a header defines (`#define`
/// lines of other forms are skipped).
fn uint_defines(text: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        let (Some("#define"), Some(name), Some(value), None) = (words.next(), words.next(), words.next(), words.next()) else { continue };
        let Some(digits) = value.strip_suffix('u') else { continue };
        let parsed = match digits.strip_prefix("0x") {
            Some(hex) => u32::from_str_radix(hex, 16),
            None => digits.parse(),
        };
        if parsed.is_ok() {
            out.push((name.to_owned(), digits.to_owned()));
        }
    }
    out
}

/// The Rust of common.glsl's numbers: `debug_view.rs` (`DEBUG_VIEW_X` → `X`, and `ALL` with
/// the GLSL names) and `common_defines.rs` (the others, named as in the GLSL).
fn write_defines(common: &Path, out_dir: &Path) {
    let text = std::fs::read_to_string(common).unwrap_or_else(|e| panic!("{}: {e}", common.display()));
    let (mut views, mut others) = (String::new(), String::new());
    let mut all = String::from(
        "/// Every code with its name in the GLSL, in the order common.glsl defines them.\npub const ALL: &[(&str, u32)] = &[\n",
    );
    for (name, value) in uint_defines(&text) {
        match name.strip_prefix("DEBUG_VIEW_") {
            Some(view) => {
                views.push_str(&format!("/// `{name}`.\npub const {view}: u32 = {value};\n"));
                all.push_str(&format!("    ({name:?}, {value}),\n"));
            }
            None => others.push_str(&format!("/// `{name}`.\npub const {name}: u32 = {value};\n")),
        }
    }
    assert!(!views.is_empty(), "{}: no #define DEBUG_VIEW_* Nu lines", common.display());
    for line in text.lines().filter(|l| l.trim_start().starts_with("#define DEBUG_VIEW_")) {
        assert!(uint_defines(line).len() == 1, "{}: `{line}` is not `#define DEBUG_VIEW_NAME Nu`", common.display());
    }
    all.push_str("];\n");
    std::fs::write(out_dir.join("debug_view.rs"), views + &all).unwrap();
    std::fs::write(out_dir.join("common_defines.rs"), others).unwrap();
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
    let mut index = String::new();
    let mut all = String::from("/// Every compiled shader, for reflection tests.\npub const ALL: &[Shader] = &[\n");
    // Constant name → file: names come from file names alone, so two folders must not hold
    // one name.
    let mut names: BTreeMap<String, String> = BTreeMap::new();
    for path in files_under(&shader_dir) {
        println!("cargo:rerun-if-changed={}", path.display());
        let Some(stage) = stage_of(&path) else { continue };
        let file = path.strip_prefix(&shader_dir).unwrap().to_str().unwrap().replace('\\', "/");
        let file_name = path.file_name().unwrap().to_str().unwrap();
        let const_name = file_name.replace('.', "_").to_uppercase();
        if let Some(other) = names.insert(const_name.clone(), file.clone()) {
            panic!("shaders/{file} and shaders/{other} would both be ml_shaders::{const_name}: rename one");
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let source = ShaderSource::from(text);
        let mut includes = RootIncludes(shader_dir.clone());
        let input = ShaderInput::new(&source, stage, &options, None::<&[(&str, Option<&str>)]>, Some(&mut includes))
            .unwrap_or_else(|e| panic!("shaders/{file}: {e}"));
        let shader = glslang::Shader::new(compiler, input).parse().unwrap_or_else(|e| panic!("shaders/{file}: {e}"));
        let words = shader.compile().unwrap_or_else(|e| panic!("shaders/{file}: {e}"));
        let spv_name = format!("{const_name}.spv");
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        std::fs::write(out_dir.join(&spv_name), bytes).unwrap();
        let Reflected { bindings, spec_constants, workgroup_size } = reflect(&file, stage, &words);
        index.push_str(&format!(
            "/// `shaders/{file}`.\npub const {const_name}: Shader = Shader {{ file: {file:?}, spirv: include_bytes!(concat!(env!(\"OUT_DIR\"), \"/{spv_name}\")), bindings: &[{bindings}], spec_constants: &[{spec_constants}], workgroup_size: {workgroup_size:?} }};\n"
        ));
        all.push_str(&format!("    {const_name},\n"));
    }
    index.push_str(&all);
    index.push_str("];\n");
    std::fs::write(out_dir.join("shaders.rs"), index).unwrap();
    write_defines(&shader_dir.join("common/common.glsl"), &out_dir);
}
