#!/usr/bin/env bash
# The gates CI runs before the tests: formatting (rustfmt), lints (clippy, every warning an
# error) and the crate docs (rustdoc, every warning an error: broken links, bad code blocks).
# rustfmt and clippy come with rustup's default profile; where rustup is there and they are
# not, they are added.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! cargo fmt --version >/dev/null 2>&1 || ! cargo clippy --version >/dev/null 2>&1; then
  command -v rustup >/dev/null || { echo "error: cargo fmt and cargo clippy are missing: install Rust with rustup (https://rustup.rs)" >&2; exit 1; }
  rustup component add rustfmt clippy
fi
echo "lint: cargo fmt --check" >&2
cargo fmt --all -- --check
# Both with the test profile, the one `cargo test` builds with: the dependencies' build scripts
# (glslang's C++ above all) then run once for the gates and the tests, not once per profile.
# ml-cpu's criterion feature: its benchmark is a target too (the test build leaves criterion out).
echo "lint: cargo clippy -D warnings" >&2
cargo clippy --profile test --workspace --all-targets --features ml-cpu/criterion --locked -q -- -D warnings
echo "lint: cargo doc -D warnings" >&2
RUSTDOCFLAGS=-Dwarnings cargo doc --profile test --no-deps --workspace --locked -q
