#!/usr/bin/env bash
# The main job: render the built-in seed scene headless to seed.png and print the timing table.
# Extra arguments go to `manylights render` (e.g. --lights 4096 --width 1920 --height 1080).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
if [ ! -x target/release/manylights ]; then
    echo "Building manylights (release). The first build compiles every dependency: about 10-20 minutes on 2 cores, a few on 16; later builds take seconds." >&2
fi
# Without -q: cargo's progress shows while it builds.
cargo build --release --locked -p manylights
./target/release/manylights render --out seed.png "$@"
