#!/usr/bin/env bash
# Every test: the lint gates (scripts/lint.sh: fmt, clippy, docs), then CPU unit tests and GPU
# image tests on whatever Vulkan device is present (lavapipe in CI), with the validation layers
# and synchronization validation on.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh tests
bash scripts/lint.sh
cargo test --workspace --locked "$@"
