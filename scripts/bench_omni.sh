#!/usr/bin/env bash
# The point-light shadow measurement (docs/BENCHMARKS.md#point-light-shadow-cubes-the-graphics-modes-and-the-compute-raster):
# GPU ms of the shadow pass (every cube rendered every
# frame) for 1, 4 and 16 shadowed lights, cube faces of 1024², by each way of filling the
# cubes (the four graphics modes and the compute raster); the seed scene (49 spheres, the seed's 64 grid lights of radius 15), 1280×720,
# seed shading with forward. Usage: scripts/bench_omni.sh [BINARY] [OUTDIR] [FRAMES]
# A mode the device refuses (multiview on lavapipe) prints its one-line reason.
set -euo pipefail
bin=${1:-target/release/manylights}
out=${2:-bench-omni}
frames=${3:-20}
mkdir -p "$out"
for k in 1 4 16; do
  for mode in copy direct multiview layered compute; do
    echo "== $mode, $k shadowed lights, $frames frames"
    "$bin" render --omni-shadow "$mode" --shadowed-lights "$k" --cube-size "${CUBE:-1024}" --width 1280 --height 720 \
      --frames "$frames" --out "$out/$mode-$k.png" 2>&1 | grep -E "omni shadows pass|shadow raster|device|error" || true
  done
done
