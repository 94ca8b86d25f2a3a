#!/usr/bin/env bash
# Installs pbflow's Debian 12 packages (only when one is missing) and builds build/pbflow.
# Usage: scripts/setup.sh            -> packages + Release build
#        scripts/setup.sh --test     -> also what only the tests need (ffmpeg, to test --video)
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake pkg-config
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers glslc
  libglm-dev libegl-dev libegl-mesa0 libgl1-mesa-dri libepoxy-dev libpng-dev
  nlohmann-json3-dev libcli11-dev googletest libgtest-dev
  python3-matplotlib
)
if [[ "${1:-}" == "--test" ]]; then
  packages+=(ffmpeg)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "pbflow setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update
  apt-get install -y --no-install-recommends "${missing[@]}"
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
