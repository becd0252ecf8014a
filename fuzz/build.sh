#!/usr/bin/env bash
# Builds the fuzz targets of the loaders (fuzz/fuzz_targets: gltf, glb, scene_file, image,
# scene_gltf) with cargo-fuzz: libFuzzer, optimised, with debug assertions and overflow
# checks, no sanitizer (the loaders are safe Rust; a panic, an overflow, a time-out or
# running out of memory is what a run finds). The binaries land in
# fuzz/target/x86_64-unknown-linux-gnu/release/; fuzz/run.sh runs them. Stable Rust needs
# RUSTC_BOOTSTRAP=1 for the flags cargo-fuzz uses.
# Usage: bash fuzz/build.sh   (about 5 minutes on 2 cores the first time)
set -euo pipefail
cd "$(dirname "$0")/.."
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
RUSTC_BOOTSTRAP=1 cargo fuzz build --fuzz-dir fuzz --sanitizer none
ls -l fuzz/target/x86_64-unknown-linux-gnu/release/{gltf,glb,scene_file,image,scene_gltf}
