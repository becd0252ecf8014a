#!/usr/bin/env bash
# Installs what manylights needs to run on a Debian/Ubuntu machine, and only what is missing:
# the Vulkan loader, Mesa's CPU Vulkan driver (lavapipe), the Khronos validation layers, and
# for the viewer the X11 client libraries winit loads and a virtual X server (its CI test);
# with the argument `tests`, also SPIRV-Tools (a shader test optimises SPIR-V with spirv-opt)
# and Slurm with munge (a test runs an image sequence as a job array on a one-machine cluster).
# Rust (cargo) must already be there: https://rustup.rs
set -euo pipefail
needed=(libvulkan1 mesa-vulkan-drivers vulkan-validationlayers
  # the viewer's window (winit on X11) and its CI test (a virtual X server)
  libx11-xcb1 libxcursor1 libxi6 libxrandr2 libxkbcommon-x11-0 xvfb xauth)
[ "${1:-}" != tests ] || needed+=(spirv-tools slurm-wlm munge)
missing=()
for p in "${needed[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
command -v cargo >/dev/null || { echo "error: cargo not found: install Rust with rustup (https://rustup.rs)" >&2; exit 1; }
