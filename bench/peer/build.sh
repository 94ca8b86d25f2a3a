#!/usr/bin/env bash
# Builds the CPU peer, SPlisHSPlasH at a pinned commit (Release, ~10 min on two cores), once,
# and prints its simulator's absolute path (bench/peer.sh, bench/peer/boundary.sh).
# The checkout: $PEER_SRC (any path; default bench_out/peer/SPlisHSPlasH), cloned when absent;
# a machine without network brings its own. Its GUI library needs X11 headers, installed here
# as scripts/setup.sh installs packages.
#   bench/peer/build.sh   -> /abs/path/to/SPlisHSPlasH/bin/SPHSimulator
set -euo pipefail
cd "$(dirname "$0")/../.."
commit=c5a063ddd33d0172ce951f412fec769929ff57ee
# Absolute: the peer resolves a scene's relative paths against its own bin/.
src="$(realpath -m "${PEER_SRC:-bench_out/peer/SPlisHSPlasH}")"
sim="$src/bin/SPHSimulator"
if [ ! -x "$sim" ]; then
  if [ ! -d "$src" ]; then
    git clone https://github.com/InteractiveComputerGraphics/SPlisHSPlasH "$src" >&2 ||
      { echo "build.sh: cannot clone SPlisHSPlasH (no network?): set PEER_SRC to a checkout" >&2; exit 1; }
    git -C "$src" checkout -q "$commit"
  fi
  scripts/install-packages.sh libxrandr-dev libxinerama-dev libxcursor-dev libxi-dev libgl-dev >&2
  cmake -S "$src" -B "$src/build" -DCMAKE_BUILD_TYPE=Release -DUSE_PYTHON_BINDINGS=OFF >&2
  cmake --build "$src/build" --target SPHSimulator -j "$(nproc)" >&2
fi
echo "$sim"
