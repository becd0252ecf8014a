#!/usr/bin/env bash
# Every test: CPU unit tests and GPU image tests on whatever Vulkan device is present
# (lavapipe in CI), with the validation layers and synchronization validation on.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo test --workspace --locked "$@"
