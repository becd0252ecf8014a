#!/usr/bin/env bash
# Runs one fuzz target, built already by fuzz/build.sh (this script builds nothing), for
# SECONDS, and prints how many inputs it ran and how many crashes it found (a crash's input
# is kept under ARTIFACTS; exit status 1 if there was one).
# Usage: bash fuzz/run.sh TARGET SECONDS [CORPUS_DIR] [JOBS]
#   TARGET      gltf (glTF JSON), glb, scene_file (TOML), image (a texture's bytes) or
#               scene_gltf (a scene file and the glTF it places)
#   CORPUS_DIR  where the corpus grows (default fuzz/corpus/TARGET); fuzz/seed-corpus/TARGET
#               is read as well
#   JOBS        processes (default 1; more runs libFuzzer's fork mode, which goes on past a
#               crash and counts them)
# Environment: FUZZ_BIN_DIR (default fuzz/target/x86_64-unknown-linux-gnu/release),
#   ARTIFACTS (default fuzz/artifacts/TARGET).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if [ $# -lt 2 ]; then
  sed -n '2,14p' "$0" >&2
  exit 2
fi
target=$1
seconds=$2
corpus=${3:-$here/corpus/$target}
jobs=${4:-1}
binary=${FUZZ_BIN_DIR:-$here/target/x86_64-unknown-linux-gnu/release}/$target
artifacts=${ARTIFACTS:-$here/artifacts/$target}
seeds=$here/seed-corpus/$target
if [ ! -x "$binary" ]; then
  echo "error: no fuzz binary '$binary': build it with 'bash fuzz/build.sh'" >&2
  exit 2
fi
mkdir -p "$corpus" "$artifacts"
log=$(mktemp)
found_before=$(find "$artifacts" -type f | wc -l)
# Limits: an input gets 10 s and 4 GiB (the loaders' caps allow about 1 GiB at once), inputs
# up to 1 MiB.
options=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 -max_len=1048576 -print_final_stats=1
  -artifact_prefix="$artifacts/")
if [ "$jobs" -gt 1 ]; then
  options+=(-fork="$jobs" -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
fi
status=0
"$binary" "${options[@]}" "$corpus" "$seeds" >"$log" 2>&1 || status=$?
tail -n 20 "$log"
# One process prints its count in its final stats; fork mode in its last progress line (#N).
executions=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | grep -o '[0-9]*$' | tail -n 1 || true)
if [ -z "$executions" ]; then
  executions=$(grep -o '^#[0-9]*' "$log" | tr -d '#' | tail -n 1 || true)
fi
crashes=$(($(find "$artifacts" -type f | wc -l) - found_before))
echo "== $target: $seconds s, $jobs job(s): ${executions:-?} executions, $crashes crashes (libFuzzer exit status $status; log $log)"
if [ "$crashes" -gt 0 ]; then
  find "$artifacts" -type f -newer "$log" -print
  exit 1
fi
