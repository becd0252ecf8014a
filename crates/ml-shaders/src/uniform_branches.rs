//! No shader branches on push constants and uniform-block values alone.
//!
//! Mesa's lavapipe, the CPU driver CI renders with, looks in every shader for `if`
//! conditions and loop bounds that depend on nothing but push constants and uniform-buffer
//! values read at constant offsets. It then compiles the shader again at every pipeline bind,
//! those values written in as constants ("uniform inlining", Mesa 22.3), a quarter of a second
//! for a lighting shader: every frame of every multi-frame test paid it. The frame's values
//! live in a storage buffer, which it never inlines, and the shaders read such push constants
//! through `opaque_uniform` (common.glsl), which that search does not look through.
//!
//! This test looks for what lavapipe looks for, in SSA form close to what lavapipe sees (the
//! driver's own form may find more, which is why the frame's values are kept out of reach
//! altogether): each shader
//! optimised by `spirv-opt` (SPIRV-Tools; `scripts/setup.sh tests` installs it) — functions
//! inlined, specialization constants frozen at their defaults and again with every boolean
//! one true, so that code behind each feature switch is seen — then every conditional branch
//! and switch whose condition is computed from constants and uniform loads alone, and every
//! comparison of a loop's induction variable (a phi) with such a value.

use super::{ALL, UNIFORM_BRANCH_PROBE_COMP as PROBE};
use std::collections::{BTreeSet, HashMap};
use std::process::Command;

/// Opcodes this test reads (SPIR-V specification, section 3.49).
mod op {
    pub const NAME: u32 = 5;
    pub const MEMBER_NAME: u32 = 6;
    pub const EXT_INST: u32 = 12;
    pub const TYPE_VECTOR: u32 = 23;
    pub const TYPE_MATRIX: u32 = 24;
    pub const TYPE_ARRAY: u32 = 28;
    pub const TYPE_RUNTIME_ARRAY: u32 = 29;
    pub const TYPE_STRUCT: u32 = 30;
    pub const TYPE_POINTER: u32 = 32;
    pub const CONSTANT_TRUE: u32 = 41;
    pub const CONSTANT_FALSE: u32 = 42;
    pub const CONSTANT: u32 = 43;
    pub const CONSTANT_COMPOSITE: u32 = 44;
    pub const CONSTANT_NULL: u32 = 46;
    pub const SPEC_CONSTANT_TRUE: u32 = 48;
    pub const SPEC_CONSTANT_FALSE: u32 = 49;
    pub const VARIABLE: u32 = 59;
    pub const LOAD: u32 = 61;
    pub const ACCESS_CHAIN: u32 = 65;
    pub const IN_BOUNDS_ACCESS_CHAIN: u32 = 66;
    pub const DECORATE: u32 = 71;
    pub const VECTOR_SHUFFLE: u32 = 79;
    pub const COMPOSITE_CONSTRUCT: u32 = 80;
    pub const COMPOSITE_EXTRACT: u32 = 81;
    pub const COMPOSITE_INSERT: u32 = 82;
    pub const COPY_OBJECT: u32 = 83;
    pub const TRANSPOSE: u32 = 84;
    pub const PHI: u32 = 245;
    pub const BRANCH_CONDITIONAL: u32 = 250;
    pub const SWITCH: u32 = 251;
    /// Conversions (OpConvertFToU .. OpBitcast).
    pub const CONVERSIONS: std::ops::RangeInclusive<u32> = 109..=124;
    /// Arithmetic (OpSNegate .. OpDot).
    pub const ARITHMETIC: std::ops::RangeInclusive<u32> = 126..=148;
    /// OpAny .. OpIsInf, logic, OpSelect and comparisons (.. OpFUnordGreaterThanEqual).
    pub const TESTS: std::ops::RangeInclusive<u32> = 154..=191;
    /// Comparisons (OpIEqual .. OpFUnordGreaterThanEqual).
    pub const COMPARISONS: std::ops::RangeInclusive<u32> = 170..=191;
    /// Bit operations (OpShiftRightLogical .. OpBitCount).
    pub const BITS: std::ops::RangeInclusive<u32> = 194..=205;
}

/// Storage classes of the values lavapipe inlines.
const UNIFORM: u32 = 2;
const PUSH_CONSTANT: u32 = 9;
/// Decoration SpecId.
const SPEC_ID: u32 = 1;

fn words_of(bytes: &[u8]) -> Vec<u32> {
    bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect()
}

/// Each instruction after the header: (opcode, operand words).
fn instructions(words: &[u32]) -> Vec<(u32, &[u32])> {
    let mut out = Vec::new();
    let mut at = 5;
    while at < words.len() {
        let (count, opcode) = ((words[at] >> 16) as usize, words[at] & 0xffff);
        out.push((opcode, &words[at + 1..at + count.max(1)]));
        at += count.max(1);
    }
    out
}

fn string(words: &[u32]) -> String {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).take_while(|&b| b != 0).collect();
    String::from_utf8_lossy(&bytes).into_owned()
}

/// The spec ids of the module's boolean specialization constants.
fn boolean_spec_ids(words: &[u32]) -> Vec<u32> {
    let insts = instructions(words);
    let spec_id: HashMap<u32, u32> =
        insts.iter().filter(|(o, w)| *o == op::DECORATE && w.len() == 3 && w[1] == SPEC_ID).map(|(_, w)| (w[0], w[2])).collect();
    insts
        .iter()
        .filter(|(o, _)| *o == op::SPEC_CONSTANT_TRUE || *o == op::SPEC_CONSTANT_FALSE)
        .filter_map(|(_, w)| spec_id.get(&w[1]).copied())
        .collect()
}

/// `spirv` optimised by spirv-opt: specialization constants frozen (`values`: "id:value ..."
/// over the defaults), functions inlined, dead code and variables removed.
fn optimised(name: &str, spirv: &[u8], values: &str) -> Vec<u32> {
    let dir = std::env::temp_dir().join(format!("ml-uniform-branches-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (input, output) = (dir.join(format!("{name}.spv")), dir.join(format!("{name}.opt.spv")));
    std::fs::write(&input, spirv).unwrap();
    let mut cmd = Command::new("spirv-opt");
    if !values.is_empty() {
        cmd.arg(format!("--set-spec-const-default-value={values}"));
    }
    let run = cmd
        .args(["--freeze-spec-const", "-O", "--skip-validation"])
        .arg(&input)
        .arg("-o")
        .arg(&output)
        .output()
        .unwrap_or_else(|e| panic!("spirv-opt (SPIRV-Tools; `bash scripts/setup.sh tests` installs it): {e}"));
    assert!(run.status.success(), "spirv-opt {name}: {}", String::from_utf8_lossy(&run.stderr));
    let words = words_of(&std::fs::read(&output).unwrap());
    let _ = std::fs::remove_file(&input);
    let _ = std::fs::remove_file(&output);
    words
}

/// A value's definition: opcode, result type, operands after the result id.
#[derive(Clone, Copy)]
struct Def<'a> {
    op: u32,
    ty: u32,
    args: &'a [u32],
}

/// An optimised module, as far as this test reads it.
struct Module<'a> {
    /// Values by result id.
    values: HashMap<u32, Def<'a>>,
    /// Types by result id: opcode, operands after the id.
    types: HashMap<u32, (u32, &'a [u32])>,
    names: HashMap<u32, String>,
    member_names: HashMap<(u32, u32), String>,
}

impl<'a> Module<'a> {
    fn new(insts: &[(u32, &'a [u32])]) -> Module<'a> {
        let mut m = Module { values: HashMap::new(), types: HashMap::new(), names: HashMap::new(), member_names: HashMap::new() };
        for &(o, w) in insts {
            match o {
                op::NAME => {
                    m.names.insert(w[0], string(&w[1..]));
                }
                op::MEMBER_NAME => {
                    m.member_names.insert((w[0], w[1]), string(&w[2..]));
                }
                op::TYPE_VECTOR | op::TYPE_MATRIX | op::TYPE_ARRAY | op::TYPE_RUNTIME_ARRAY | op::TYPE_STRUCT | op::TYPE_POINTER => {
                    m.types.insert(w[0], (o, &w[1..]));
                }
                _ if w.len() >= 2 && has_result(o) => {
                    m.values.insert(w[1], Def { op: o, ty: w[0], args: &w[2..] });
                }
                _ => {}
            }
        }
        m
    }

    fn constant(&self, id: u32) -> Option<u32> {
        self.values.get(&id).filter(|d| d.op == op::CONSTANT).and_then(|d| d.args.first().copied())
    }

    /// `Block.member.x`: a load at constant `indices` into `variable`.
    fn describe(&self, variable: u32, indices: &[u32]) -> String {
        let mut ty = match self.types.get(&self.values[&variable].ty) {
            Some(&(op::TYPE_POINTER, w)) => w[1],
            _ => 0,
        };
        let mut out = vec![self.names.get(&ty).cloned().unwrap_or_else(|| format!("%{ty}"))];
        for &i in indices {
            let k = self.constant(i).unwrap_or(0);
            match self.types.get(&ty) {
                Some(&(op::TYPE_STRUCT, members)) => {
                    out.push(self.member_names.get(&(ty, k)).cloned().unwrap_or_else(|| k.to_string()));
                    ty = members[k as usize];
                }
                Some(&(op::TYPE_VECTOR, w)) => {
                    out.push(["x", "y", "z", "w"][k as usize % 4].to_owned());
                    ty = w[0];
                }
                Some(&(_, w)) => {
                    out.push(format!("[{k}]"));
                    ty = w[0];
                }
                None => out.push("?".into()),
            }
        }
        out.join(".")
    }

    /// The uniform values `id` is computed from, if it is computed from nothing else
    /// (constants and loads at constant offsets from uniform blocks and push constants,
    /// through arithmetic, logic, conversions, composites and GLSL.std.450): lavapipe could
    /// inline them. None where anything else enters.
    fn uniform_only(&self, id: u32, memo: &mut HashMap<u32, Option<BTreeSet<String>>>) -> Option<BTreeSet<String>> {
        if let Some(known) = memo.get(&id) {
            return known.clone();
        }
        memo.insert(id, None); // a cycle (through a phi) is not uniform
        let def = *self.values.get(&id)?;
        let all = |ids: &[u32], memo: &mut HashMap<u32, Option<BTreeSet<String>>>| {
            let mut out = BTreeSet::new();
            for &i in ids {
                out.extend(self.uniform_only(i, memo)?);
            }
            Some(out)
        };
        let found = match def.op {
            op::CONSTANT_TRUE | op::CONSTANT_FALSE | op::CONSTANT | op::CONSTANT_COMPOSITE | op::CONSTANT_NULL => Some(BTreeSet::new()),
            op::LOAD => {
                let pointer = def.args[0];
                let (variable, indices): (u32, &[u32]) = match self.values.get(&pointer) {
                    Some(d) if d.op == op::ACCESS_CHAIN || d.op == op::IN_BOUNDS_ACCESS_CHAIN => (d.args[0], &d.args[1..]),
                    _ => (pointer, &[]),
                };
                let class = self.values.get(&variable).filter(|d| d.op == op::VARIABLE).map(|d| d.args[0]);
                let constant_offset = indices.iter().all(|&i| self.constant(i).is_some());
                (matches!(class, Some(UNIFORM | PUSH_CONSTANT)) && constant_offset)
                    .then(|| BTreeSet::from([self.describe(variable, indices)]))
            }
            op::EXT_INST => all(&def.args[2..], memo),
            op::COMPOSITE_EXTRACT => all(&def.args[..1], memo),
            op::COMPOSITE_INSERT | op::VECTOR_SHUFFLE => all(&def.args[..2], memo),
            op::COMPOSITE_CONSTRUCT | op::COPY_OBJECT | op::TRANSPOSE => all(def.args, memo),
            o if op::CONVERSIONS.contains(&o) || op::ARITHMETIC.contains(&o) || op::TESTS.contains(&o) || op::BITS.contains(&o) => {
                all(def.args, memo)
            }
            _ => None,
        };
        memo.insert(id, found.clone());
        found
    }
}

fn has_result(o: u32) -> bool {
    matches!(
        o,
        op::EXT_INST
            | op::CONSTANT_TRUE
            | op::CONSTANT_FALSE
            | op::CONSTANT
            | op::CONSTANT_COMPOSITE
            | op::CONSTANT_NULL
            | op::VARIABLE
            | op::LOAD
            | op::ACCESS_CHAIN
            | op::IN_BOUNDS_ACCESS_CHAIN
            | op::VECTOR_SHUFFLE
            | op::COMPOSITE_CONSTRUCT
            | op::COMPOSITE_EXTRACT
            | op::COMPOSITE_INSERT
            | op::COPY_OBJECT
            | op::TRANSPOSE
            | op::PHI
    ) || op::CONVERSIONS.contains(&o)
        || op::ARITHMETIC.contains(&o)
        || op::TESTS.contains(&o)
        || op::BITS.contains(&o)
}

/// The branches of an optimised module that rest on uniform values alone, described.
fn uniform_branches(words: &[u32]) -> Vec<String> {
    let insts = instructions(words);
    let m = Module::new(&insts);
    let mut memo = HashMap::new();
    let mut found = Vec::new();
    for &(o, w) in &insts {
        let condition = match o {
            op::BRANCH_CONDITIONAL | op::SWITCH => w[0],
            _ => continue,
        };
        let what = if o == op::SWITCH { "switch" } else { "branch" };
        match m.uniform_only(condition, &mut memo) {
            Some(values) if !values.is_empty() => found.push(format!("{what} on {values:?}")),
            _ => {}
        }
        // A loop's bound: its induction variable (a phi) compared with uniform values.
        if let Some(def) = m.values.get(&condition).filter(|d| op::COMPARISONS.contains(&d.op)) {
            for (a, b) in [(def.args[0], def.args[1]), (def.args[1], def.args[0])] {
                let induction = m.values.get(&a).is_some_and(|d| d.op == op::PHI);
                match m.uniform_only(b, &mut memo) {
                    Some(values) if induction && !values.is_empty() => found.push(format!("loop bound {values:?}")),
                    _ => {}
                }
            }
        }
    }
    found
}

/// What the search finds in one shader, under both sets of constants.
fn shader_failures(shader: &crate::Shader) -> Vec<String> {
    let name = shader.file.replace('/', "_");
    let words = words_of(shader.spirv);
    let all_on: Vec<String> = boolean_spec_ids(&words).iter().map(|id| format!("{id}:true")).collect();
    let mut failures = Vec::new();
    for values in [String::new(), all_on.join(" ")] {
        for branch in uniform_branches(&optimised(&name, shader.spirv, &values)) {
            failures.push(format!("{} (constants {}): {branch}", shader.file, if values.is_empty() { "default" } else { "on" }));
        }
    }
    failures.dedup();
    failures
}

#[test]
fn no_branch_rests_on_uniforms_alone() {
    let mut shaders: Vec<&crate::Shader> = ALL.iter().filter(|s| s.file != PROBE.file).collect();
    // spirv-opt runs about a hundred times a set of constants, its time growing with the
    // shader: on every core, each taking the largest shader left, so that no core is left
    // with the lighting shaders at the end.
    shaders.sort_by_key(|s| std::cmp::Reverse(s.spirv.len()));
    let next = std::sync::atomic::AtomicUsize::new(0);
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let mut failures: Vec<(usize, Vec<String>)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut found = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(shader) = shaders.get(i) else { break found };
                        found.push((i, shader_failures(shader)));
                    }
                })
            })
            .collect();
        workers.into_iter().flat_map(|w| w.join().unwrap()).collect()
    });
    failures.sort_by_key(|(i, _)| *i);
    let failures: Vec<String> = failures.into_iter().flat_map(|(_, f)| f).collect();
    assert!(failures.is_empty(), "read these through opaque_uniform (common.glsl):\n{}", failures.join("\n"));
}

/// The search finds what it looks for: the probe's branch on a push constant and its loop up
/// to a count in a uniform block.
#[test]
fn the_search_finds_the_probes_uniform_branches() {
    let found = uniform_branches(&optimised("probe", PROBE.spirv, ""));
    assert_eq!(
        found,
        ["branch on {\"UniformBranchPushBlock.mode.x\"}".to_owned(), "loop bound {\"UniformBranchBlock.counts.x\"}".to_owned()],
        "{found:?}"
    );
}
