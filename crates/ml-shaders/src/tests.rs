//! The reflection against the GLSL text: what the build script reports of each shader must be
//! what its source (with its headers) declares, read here by a plain text scan.

use super::*;
use std::collections::BTreeMap;
use std::path::PathBuf;

fn shader_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shaders")
}

/// The lines of `shaders/<file>` with every `#include` (a path under `shaders/`) replaced by
/// the header's lines, once each (the headers have include guards).
fn source_lines(file: &str, seen: &mut Vec<String>) -> Vec<String> {
    let path = shader_root().join(file);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut out = Vec::new();
    for line in text.lines() {
        match line.trim().strip_prefix("#include \"").and_then(|rest| rest.strip_suffix('"')) {
            Some(header) if !seen.iter().any(|s| s == header) => {
                seen.push(header.to_owned());
                out.extend(source_lines(header, seen));
            }
            Some(_) => {}
            None => out.push(line.trim().to_owned()),
        }
    }
    out
}

/// `layout(constant_id = N) const TYPE NAME = ...;` declarations: name → id.
fn declared_constants(lines: &[String]) -> BTreeMap<String, u32> {
    let mut out = BTreeMap::new();
    for line in lines {
        let Some(rest) = line.strip_prefix("layout(constant_id = ") else { continue };
        let (id, decl) = rest.split_once(')').expect("layout(constant_id = N)");
        let name = decl.split('=').next().unwrap().split_whitespace().last().expect("a name");
        out.insert(name.to_owned(), id.trim().parse().expect("a number"));
    }
    out
}

/// The `layout(local_size_x = X, ...) in;` of a compute shader, unnamed axes 1.
fn declared_local_size(lines: &[String]) -> Option<[u32; 3]> {
    let line = lines.iter().find(|l| l.starts_with("layout(local_size_") && l.ends_with(") in;"))?;
    let inner = line.strip_prefix("layout(").unwrap().strip_suffix(") in;").unwrap();
    let mut size = [1; 3];
    for part in inner.split(',') {
        let (axis, value) = part.split_once('=').expect("local_size_? = N");
        let i = ["local_size_x", "local_size_y", "local_size_z"].iter().position(|a| *a == axis.trim()).expect("an axis");
        size[i] = value.trim().parse().expect("a number");
    }
    Some(size)
}

#[test]
fn every_shader_reflects_what_its_glsl_declares() {
    let mut with_constants = 0;
    for shader in ALL {
        let lines = source_lines(shader.file, &mut Vec::new());
        let declared = declared_constants(&lines);
        let reflected: BTreeMap<String, u32> = shader.spec_constants.iter().map(|c| (c.name.to_owned(), c.id)).collect();
        assert_eq!(reflected, declared, "{}", shader.file);
        for c in shader.spec_constants {
            assert_eq!(shader.spec_id(c.name), Some(c.id));
        }
        with_constants += usize::from(!shader.spec_constants.is_empty());
        let expected = if shader.file.ends_with(".comp") {
            declared_local_size(&lines).unwrap_or_else(|| panic!("{}: no local size", shader.file))
        } else {
            [1, 1, 1]
        };
        assert_eq!(shader.workgroup_size, expected, "{}", shader.file);
    }
    assert!(with_constants > 10, "only {with_constants} shaders hold specialization constants");
}

#[test]
fn known_shaders_have_their_glsl_numbers() {
    // light_grid_build.comp: local_size_x = 256; constant_id 0 STEP.
    assert_eq!(LIGHT_GRID_BUILD_COMP.file, "light_grid/light_grid_build.comp");
    assert_eq!(LIGHT_GRID_BUILD_COMP.workgroup_size, [256, 1, 1]);
    assert_eq!(LIGHT_GRID_BUILD_COMP.spec_constants, &[SpecConstant { name: "STEP", id: 0 }]);
    assert_eq!(LIGHT_GRID_BUILD_COMP.spec_id("SOURCE"), None);
    // tonemap.comp: 8×8, and the shading model's constants from common/shading_model.glsl.
    assert_eq!(TONEMAP_COMP.workgroup_size, [8, 8, 1]);
    assert_eq!(TONEMAP_COMP.spec_id("MODEL_PBR"), Some(11));
    assert_eq!(TONEMAP_COMP.groups([17, 16, 1]), [3, 2, 1]);
    // A fragment shader: constants of several headers, no work groups.
    assert_eq!(FORWARD_FRAG.workgroup_size, [1, 1, 1]);
    for (name, id) in [("MODEL_BLINN_PHONG", 10), ("OMNI_SHADOWS", 12), ("SPOT_LIGHTS", 14), ("MASKED_DRAW", 16)] {
        assert_eq!(FORWARD_FRAG.spec_id(name), Some(id), "{name}");
    }
}

#[test]
fn every_debug_view_define_is_generated() {
    let path = shader_root().join("common/common.glsl");
    let text = std::fs::read_to_string(&path).unwrap();
    let defined: Vec<(String, u32)> = text
        .lines()
        .filter_map(|l| l.strip_prefix("#define DEBUG_VIEW_"))
        .map(|rest| {
            let (name, value) = rest.split_once(' ').expect("#define DEBUG_VIEW_NAME Nu");
            (format!("DEBUG_VIEW_{name}"), value.trim().strip_suffix('u').expect("an unsigned number").parse().unwrap())
        })
        .collect();
    let generated: Vec<(String, u32)> = debug_view::ALL.iter().map(|&(n, v)| (n.to_owned(), v)).collect();
    assert_eq!(generated, defined);
    assert!(defined.len() >= 12);
    assert_eq!((debug_view::NONE, debug_view::CLUSTER_HEAT, debug_view::ALPHA), (0, 1, 11));
    let mut codes: Vec<u32> = debug_view::ALL.iter().map(|&(_, v)| v).collect();
    codes.sort_unstable();
    codes.dedup();
    assert_eq!(codes.len(), debug_view::ALL.len(), "two views share a code");
    assert_eq!(common::NO_TILE, u32::MAX);
}

/// (set, binding) of every variable the SPIR-V decorates with both (OpDecorate DescriptorSet
/// and Binding), read from the words themselves: reflection keeps one resource per binding.
fn decorated_bindings(spirv: &[u8]) -> Vec<(u32, u32)> {
    let words: Vec<u32> = spirv.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    let (mut sets, mut bindings) = (BTreeMap::new(), BTreeMap::new());
    let mut at = 5; // after the header
    while at < words.len() {
        let (count, opcode) = ((words[at] >> 16) as usize, words[at] & 0xffff);
        // OpDecorate target decoration literal: DescriptorSet 34, Binding 33.
        if opcode == 71 && count == 4 {
            let (target, decoration, value) = (words[at + 1], words[at + 2], words[at + 3]);
            match decoration {
                34 => {
                    sets.insert(target, value);
                }
                33 => {
                    bindings.insert(target, value);
                }
                _ => {}
            }
        }
        at += count.max(1);
    }
    bindings.iter().filter_map(|(target, &binding)| Some((*sets.get(target)?, binding))).collect()
}

/// Two resources of one shader at one binding alias each other: a header's binding numbers
/// that collide with an includer's are a bug the compiler does not report.
#[test]
fn no_shader_declares_two_resources_at_one_binding() {
    for shader in ALL {
        let mut decorated = decorated_bindings(shader.spirv);
        assert!(!decorated.is_empty() || shader.bindings.is_empty(), "{}: no bindings read", shader.file);
        decorated.sort_unstable();
        for pair in decorated.windows(2) {
            assert_ne!(pair[0], pair[1], "{}: two resources at set {} binding {}", shader.file, pair[0].0, pair[0].1);
        }
    }
}

#[test]
fn files_lie_in_feature_folders_and_names_are_unique() {
    let folders = [
        "common",
        "shading",
        "visibility",
        "shadows",
        "clusters",
        "exposure",
        "probe",
        "transparency",
        "light_stats",
        "light_grid",
        "environment",
    ];
    let mut names: Vec<&str> = Vec::new();
    for shader in ALL {
        let (folder, name) = shader.file.split_once('/').unwrap_or_else(|| panic!("{} is in no folder", shader.file));
        assert!(folders.contains(&folder), "{}", shader.file);
        assert!(shader_root().join(shader.file).is_file(), "{}", shader.file);
        assert!(!names.contains(&name), "{name} twice");
        names.push(name);
    }
}
