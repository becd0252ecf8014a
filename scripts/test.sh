#!/usr/bin/env bash
# Every test: the lint gates (scripts/lint.sh: fmt, clippy, docs), then CPU unit tests and GPU
# image tests on whatever Vulkan device is present (lavapipe in CI), with the validation layers
# and synchronization validation on. Arguments go to `cargo test` (a filter, say).
# With MANYLIGHTS_TEST_128=1, the golden images and the CPU reference again with the 128-bit
# vectors lavapipe uses on CPUs without AVX, so rounding that depends on the CPU shows on any
# machine (not in CI: it took 51 s of the 20 minutes; docs/testing.md says when to run it).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh tests
bash scripts/lint.sh
cargo test --workspace --locked "$@"
if [ "${MANYLIGHTS_TEST_128:-}" = 1 ] && [ $# -eq 0 ] && [ "${LP_NATIVE_VECTOR_WIDTH:-}" != 128 ]; then
  echo "test: again with LP_NATIVE_VECTOR_WIDTH=128 (golden images, CPU reference)" >&2
  LP_NATIVE_VECTOR_WIDTH=128 cargo test --workspace --locked --test gpu -- golden:: reference::
fi
