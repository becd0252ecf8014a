#!/usr/bin/env bash
# The fidelity harness (scripts/fidelity.py): manylights against the Mitsuba 3 path tracer on
# scenes this project writes, a score per scene and side-by-side pictures in OUT (default
# target/fidelity); scene names after OUT run only those. Installs what it needs: a Python
# virtual environment with mitsuba, numpy and pillow from PyPI (in
# ~/.cache/manylights-fidelity), LLVM's shared library from apt for Mitsuba's vectorised CPU
# variant (Dr.Jit compiles through it; Debian 12's default LLVM 15 is too old for it), and the
# release build of manylights.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-target/fidelity}"
shift || true
venv="${XDG_CACHE_HOME:-$HOME/.cache}/manylights-fidelity"
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import mitsuba, numpy, PIL" 2>/dev/null; then
  command -v python3 >/dev/null || { echo "error: python3 is missing: apt-get install python3 python3-venv" >&2; exit 1; }
  python3 -m venv "$venv" || { echo "error: cannot make a Python virtual environment: apt-get install python3-venv" >&2; exit 1; }
  "$venv/bin/pip" install --quiet mitsuba numpy pillow
fi
# The newest libLLVM of version 16 or later, installed from apt where there is none.
newest_llvm() {
  ls /usr/lib/*/libLLVM*.so.* /usr/lib/llvm-*/lib/libLLVM*.so.* 2>/dev/null |
    awk '{ v = $0; sub(/.*libLLVM[-.]?(so\.)?/, "", v); if (v + 0 >= 16) print v + 0, $0 }' | sort -n | tail -1 | cut -d' ' -f2
}
llvm="$(newest_llvm)"
if [ -z "$llvm" ]; then
  package="$(apt-cache pkgnames libllvm 2>/dev/null | grep -E '^libllvm[0-9]+$' | sort -V | tail -1)"
  [ -n "$package" ] || { echo "error: no LLVM shared library of version 16 or later, and apt offers none" >&2; exit 1; }
  echo "installing: $package" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "$package"
  llvm="$(newest_llvm)"
fi
export DRJIT_LIBLLVM_PATH="$llvm"
cargo build --release --locked -q -p manylights
"$venv/bin/python" scripts/fidelity.py target/release/manylights "$out" "$@"
