#!/usr/bin/env bash
# The fidelity harness (scripts/fidelity.py): manylights against the Mitsuba 3 path tracer on
# scenes this project writes, a score per scene and side-by-side pictures in OUT (default
# target/fidelity). Installs what it needs: a Python virtual environment with mitsuba, numpy
# and pillow from PyPI (in ~/.cache/manylights-fidelity), and the release build of manylights.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-target/fidelity}"
venv="${XDG_CACHE_HOME:-$HOME/.cache}/manylights-fidelity"
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import mitsuba, numpy, PIL" 2>/dev/null; then
  command -v python3 >/dev/null || { echo "error: python3 is missing: apt-get install python3 python3-venv" >&2; exit 1; }
  python3 -m venv "$venv" || { echo "error: cannot make a Python virtual environment: apt-get install python3-venv" >&2; exit 1; }
  "$venv/bin/pip" install --quiet mitsuba numpy pillow
fi
cargo build --release --locked -q -p manylights
"$venv/bin/python" scripts/fidelity.py target/release/manylights "$out"
