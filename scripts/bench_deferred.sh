#!/usr/bin/env bash
# The deferred-shading measurement (docs/BENCHMARKS.md, "Deferred shading: two subpasses in one
# render pass"): seed scene 1920×1080, 64 lights (the seed's grid, radius 15) and
# 4,096 / 65,536 random lights of radius 1–3; GPU ms per pass of every forward and deferred
# technique. Usage: scripts/bench_deferred.sh [BINARY] [OUTDIR] [FRAMES_FAST] [FRAMES_SLOW]
# MAX_BRUTE=N skips forward and deferred (every light at every pixel) above N lights: on
# lavapipe one 65,536-light frame of those takes a quarter of an hour. SHADING=blinn-phong
# measures the blinn-phong model (docs/DESIGN.md#shading-models) instead of the seed model.
set -euo pipefail
bin=${1:-target/release/manylights}
out=${2:-bench-deferred}
fast=${3:-20}
slow=${4:-3}
mkdir -p "$out"
for lights in 64 4096 65536; do
  if [ "$lights" = 64 ]; then layout=(--light-layout grid --light-radius 15); else layout=(--light-layout random --light-radius 1..3); fi
  for t in forward clustered-cpu deferred deferred-clustered deferred-compute; do
    if [ -n "${MAX_BRUTE:-}" ] && [ "$lights" -gt "$MAX_BRUTE" ] && { [ "$t" = forward ] || [ "$t" = deferred ]; }; then
      echo "== $t, $lights lights: skipped (MAX_BRUTE=$MAX_BRUTE)"
      continue
    fi
    frames=$fast
    if [ "$lights" -ge 4096 ] && { [ "$t" = forward ] || [ "$t" = deferred ]; }; then frames=$slow; fi
    echo "== $t, $lights lights, $frames frames"
    "$bin" render --technique "$t" --lights "$lights" "${layout[@]}" --width 1920 --height 1080 \
      --shading "${SHADING:-seed}" --frames "$frames" --out "$out/$t-$lights.png" | grep -E "gpu ms|cpu assign|g-buffer|lights/cluster|device"
  done
done
