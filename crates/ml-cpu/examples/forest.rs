//! Writes a forest of cut-out leaves (`ml_cpu::forest`): trees of leaf cards on a ground
//! plane, `alphaMode: MASK` — the content alpha masks exist for, and the benchmark of their
//! cost: the same file with `--opaque` draws the same triangles as opaque squares, with
//! `--blend` as transparent leaves (`alphaMode: BLEND`: soft-edged foliage, the transparent
//! layers' cost).
//!
//! Usage: forest OUT.glb [--trees N] [--leaves-per-tree M] [--opaque | --blend]
//! (default 16 × 16 trees of 2,048 leaves: 1,048,576 leaf triangles). Each tree's mesh is
//! stored once and placed by nodes, so the file stays small whatever the count.

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = || -> ! {
        eprintln!("usage: forest OUT.glb [--trees N] [--leaves-per-tree M] [--opaque | --blend]");
        std::process::exit(2);
    };
    let Some(out) = args.first().filter(|a| !a.starts_with("--")) else { usage() };
    let number = |flag: &str, default: u32| -> u32 {
        match args.iter().position(|a| a == flag) {
            Some(i) => args.get(i + 1).and_then(|v| v.parse().ok()).filter(|&n| n > 0).unwrap_or_else(|| usage()),
            None => default,
        }
    };
    let (trees, leaves) = (number("--trees", 256), number("--leaves-per-tree", 2048));
    let mode = match (args.iter().any(|a| a == "--opaque"), args.iter().any(|a| a == "--blend")) {
        (false, false) => "MASK",
        (true, false) => "OPAQUE",
        (false, true) => "BLEND",
        (true, true) => usage(),
    };
    std::fs::write(out, ml_cpu::forest::forest_glb(trees, leaves, mode)).unwrap_or_else(|e| {
        eprintln!("error: cannot write '{out}': {e}");
        std::process::exit(1);
    });
    println!("{out}: {trees} trees of {leaves} leaves ({} leaf triangles), alphaMode {mode}", trees as u64 * leaves as u64 * 2);
}
