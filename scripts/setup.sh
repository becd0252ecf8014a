#!/usr/bin/env bash
# Installs what manylights needs to run on a Debian/Ubuntu machine, and only what is missing:
# the Vulkan loader, Mesa's CPU Vulkan driver (lavapipe) and the Khronos validation layers.
# Rust (cargo) must already be there: https://rustup.rs
set -euo pipefail
needed=(libvulkan1 mesa-vulkan-drivers vulkan-validationlayers)
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
