#!/usr/bin/env bash
# The main job: render the built-in seed scene headless to seed.png and print the timing table.
# Extra arguments go to `manylights render` (e.g. --lights 4096 --width 1920 --height 1080).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo build --release --locked -q -p manylights
./target/release/manylights render --out seed.png "$@"
