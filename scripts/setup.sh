#!/usr/bin/env bash
# Installs pbflow's Debian 12 packages (only when one is missing) and builds build/pbflow.
# Usage: scripts/setup.sh            -> packages + Release build
#        scripts/setup.sh --test     -> also what only the tests need (python3-vtk9, to read .vtp
#                                       files with VTK's own reader; chromium, its driver and
#                                       selenium, to test `pbflow serve` in a real browser)
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake pkg-config
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers glslc
  libglm-dev libegl-dev libegl-mesa0 libgl1-mesa-dri libepoxy-dev libpng-dev
  nlohmann-json3-dev libcli11-dev googletest libgtest-dev
  libboost-dev libturbojpeg0-dev libavcodec-dev libswscale-dev libavutil-dev
  python3-matplotlib ffmpeg
  libassimp-dev libopenvdb-dev libboost-iostreams-dev
  libbullet-dev
)
if [[ "${1:-}" == "--test" ]]; then
  packages+=(python3-vtk9 chromium chromium-driver python3-selenium)
fi

scripts/install-packages.sh "${packages[@]}"

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
