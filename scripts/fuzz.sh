#!/usr/bin/env bash
# Fuzz the loaders with cargo-fuzz (libFuzzer): glTF JSON, GLB and scene files (TOML), each
# loaded beside a fixture folder so that the files they name are read too; see
# docs/testing.md#fuzzing. Builds the targets (fuzz/build.sh), then runs each for
# SECONDS_PER_TARGET with JOBS processes (fuzz/run.sh). A crash leaves its input under
# fuzz/artifacts/TARGET and fails the script.
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET] [JOBS]   (default 60 s, 1 job)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
jobs=${2:-1}
bash fuzz/build.sh
status=0
for target in gltf glb scene_file; do
  bash fuzz/run.sh "$target" "$seconds" "fuzz/corpus/$target" "$jobs" || status=1
done
exit $status
