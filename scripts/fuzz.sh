#!/usr/bin/env bash
# Fuzz the glTF loader and the scene-file parser (docs/scenes.md#gltf-20-files,
# docs/scenes.md#scene-files-toml) with cargo-fuzz (libFuzzer); see docs/testing.md#fuzzing.
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET] (default 60; the loaders' thorough run used 600).
# Needs cargo-fuzz (`cargo install cargo-fuzz`); on stable Rust RUSTC_BOOTSTRAP=1 gives it the
# nightly flags it uses. Seeds come from our own writer (crates/ml-cpu/examples/fuzz_seeds.rs);
# a crash leaves its input under fuzz/artifacts/ and fails the script.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz
corpus=fuzz/corpus
cargo run -q -p ml-cpu --example fuzz_seeds -- "$corpus/gltf" "$corpus/scene_file"
for target in gltf scene_file; do
  echo "== $target, $seconds s"
  RUSTC_BOOTSTRAP=1 cargo fuzz run --fuzz-dir fuzz "$target" "$corpus/$target" -- \
    -max_total_time="$seconds" -rss_limit_mb=4096 -max_len=1048576 -print_final_stats=1
done
