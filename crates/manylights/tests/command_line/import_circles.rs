//! No crate of the workspace has an import circle: a module that, through the modules it
//! uses, ends up using itself. Circles make a crate one lump — nothing in them can be read,
//! tested or moved alone — so the layering is checked here, for every file (module) and for
//! every top-level module (a folder and all it holds counted as one).
//!
//! A module uses another where its code names `crate::path` (in `use` lists too) or
//! `super::path`; names re-exported at the crate root count as their module's. Test modules
//! (`#[cfg(test)] mod tests`) are left out: they may use anything.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Module path (`shadows::omni_shadow_pass`; the root is "") → file.
fn modules(src: &Path) -> BTreeMap<String, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("source folder").flatten() {
            let path = entry.path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let rel = path.strip_prefix(src).unwrap().with_extension("");
            let mut parts: Vec<String> = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
            if matches!(parts.last().map(String::as_str), Some("mod" | "lib" | "main")) {
                parts.pop();
            }
            if parts.last().is_some_and(|p| p == "tests") {
                continue;
            }
            out.insert(parts.join("::"), path);
        }
    }
    out
}

/// The code of a file without its comments and its test module.
fn code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).expect("readable source");
    let text = match text.find("#[cfg(test)]\nmod tests") {
        Some(i) => text[..i].to_owned(),
        None => text,
    };
    text.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n")
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Every path a `prefix::…` names in `text`, with `{a, b::{c, d}}` groups expanded.
fn paths_after(text: &str, prefix: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find(prefix) {
        let before = rest[..i].chars().last();
        rest = &rest[i + prefix.len()..];
        if before.is_some_and(is_ident) {
            continue;
        }
        expand(rest, String::new(), &mut out);
    }
    out
}

/// The paths the text at the start of `text` names, each after `base`.
fn expand(text: &str, base: String, out: &mut Vec<String>) {
    let mut path = base;
    let mut s = text;
    if s.starts_with('{') {
        return group(s, &path, out);
    }
    loop {
        let end = s.find(|c: char| !is_ident(c)).unwrap_or(s.len());
        if end == 0 {
            break;
        }
        if !path.is_empty() {
            path.push_str("::");
        }
        path.push_str(&s[..end]);
        s = &s[end..];
        if !s.starts_with("::") {
            break;
        }
        s = &s[2..];
        if s.starts_with('{') {
            return group(s, &path, out);
        }
    }
    if !path.is_empty() {
        out.push(path);
    }
}

/// The paths of the group `{a, b::{c, d}}` at the start of `text`: each comma-separated item
/// at depth 1 continues `base`.
fn group(text: &str, base: &str, out: &mut Vec<String>) {
    let (mut depth, mut start) = (0, 1);
    for (i, c) in text.char_indices() {
        match c {
            '{' => depth += 1,
            '}' | ',' if depth == 1 => {
                expand(text[start..i].trim_start(), base.to_owned(), out);
                start = i + 1;
                if c == '}' {
                    return;
                }
            }
            '}' => depth -= 1,
            _ => {}
        }
    }
}

/// The module a path names: its longest prefix that is a module (root re-exports followed).
fn module_of(path: &str, modules: &BTreeMap<String, PathBuf>, reexports: &BTreeMap<String, String>) -> Option<String> {
    let mut parts: Vec<&str> = path.split("::").collect();
    let owned;
    if let Some(m) = reexports.get(parts[0]) {
        owned = format!("{m}::{}", parts[1..].join("::"));
        parts = owned.trim_end_matches("::").split("::").collect();
    }
    (1..=parts.len()).rev().map(|k| parts[..k].join("::")).find(|c| modules.contains_key(c))
}

/// Module → the modules it uses (itself, its parents and its children left out).
fn uses(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let modules = modules(src);
    let mut reexports = BTreeMap::new();
    if let Some(root) = modules.get("") {
        for path in paths_after(&code(root), "pub use ") {
            if let Some((module, name)) = path.rsplit_once("::") {
                reexports.insert(name.to_owned(), module.to_owned());
            }
        }
    }
    let mut graph = BTreeMap::new();
    for (module, file) in &modules {
        let text = code(file);
        let parent = module.rsplit_once("::").map_or("", |(p, _)| p);
        let mut named: Vec<String> = paths_after(&text, "crate::");
        for p in paths_after(&text, "super::") {
            named.push(if parent.is_empty() { p } else { format!("{parent}::{p}") });
        }
        let related = |other: &str| {
            other == module || other.is_empty() || module.starts_with(&format!("{other}::")) || other.starts_with(&format!("{module}::"))
        };
        let used: BTreeSet<String> = named.iter().filter_map(|p| module_of(p, &modules, &reexports)).filter(|m| !related(m)).collect();
        graph.insert(module.clone(), used);
    }
    graph
}

/// A circle of `graph`, if it has one (each module once, the first again at the end).
fn circle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    // Depth-first; a module met again while still on the path closes a circle.
    fn visit(
        m: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| p == m) {
            let mut c = path[i..].to_vec();
            c.push(m.to_owned());
            return Some(c);
        }
        if done.contains(m) {
            return None;
        }
        path.push(m.to_owned());
        for next in graph.get(m).into_iter().flatten() {
            if let Some(c) = visit(next, graph, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(m.to_owned());
        None
    }
    let mut done = BTreeSet::new();
    graph.keys().find_map(|m| visit(m, graph, &mut Vec::new(), &mut done))
}

/// The graph with every module counted as its top-level module.
fn top_level(graph: &BTreeMap<String, BTreeSet<String>>) -> BTreeMap<String, BTreeSet<String>> {
    let top = |m: &str| m.split("::").next().unwrap_or("").to_owned();
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (m, used) in graph {
        let entry = out.entry(top(m)).or_default();
        entry.extend(used.iter().map(|u| top(u)).filter(|u| *u != top(m)));
    }
    out
}

fn crates() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut out: Vec<PathBuf> = std::fs::read_dir(&root).unwrap().flatten().map(|e| e.path().join("src")).filter(|p| p.is_dir()).collect();
    out.sort();
    out
}

#[test]
fn no_crate_has_an_import_circle() {
    let all = crates();
    assert!(all.len() >= 6, "expected the workspace's crates beside this one, found {all:?}");
    for src in all {
        let graph = uses(&src);
        assert!(!graph.is_empty(), "{}: no modules found", src.display());
        for (what, g) in [("module", graph.clone()), ("top-level module", top_level(&graph))] {
            if let Some(c) = circle(&g) {
                panic!("{}: a {what} import circle: {}", src.display(), c.join(" -> "));
            }
        }
    }
}

#[test]
fn the_check_finds_a_circle() {
    // The check itself: a circle through a group import, a `super::` path and a root
    // re-export is found; cutting one edge removes it.
    let dir = std::env::temp_dir().join(format!("import-circles-{}", std::process::id()));
    let src = dir.join("src");
    std::fs::create_dir_all(src.join("feature")).unwrap();
    std::fs::write(src.join("lib.rs"), "pub mod a;\npub mod feature;\npub use a::Thing;\n").unwrap();
    std::fs::write(src.join("a.rs"), "use crate::{feature::{pass::Pass, other}};\npub struct Thing;\n").unwrap();
    std::fs::write(src.join("feature/mod.rs"), "pub mod pass;\n").unwrap();
    std::fs::write(src.join("feature/pass.rs"), "// crate::a in a comment is no use\nuse super::helper;\n").unwrap();
    std::fs::write(src.join("feature/helper.rs"), "fn f() -> crate::Thing { crate::Thing }\n").unwrap();
    let found = circle(&uses(&src));
    assert!(found.as_ref().is_some_and(|c| c.len() == 4 && c.contains(&"feature::helper".to_owned())), "{found:?}");
    std::fs::write(src.join("feature/helper.rs"), "fn f() {}\n").unwrap();
    assert_eq!(circle(&uses(&src)), None);
    let _ = std::fs::remove_dir_all(&dir);
}
