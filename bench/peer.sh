#!/usr/bin/env bash
# The CPU peer beside pbflow, in the same minutes: SPlisHSPlasH's PBF (2 OpenMP threads,
# Release build) on its own dam break (bench/peer/peer_dam_break_pbf.json: 6859 particles,
# pbf@2, dt 4 ms, 2 s) and `pbflow run bench/scenes/peer_dam_break.json --no-render`,
# alternated. Why alternated: a shared machine drifts by up to 1.5x from minute to minute,
# and did so between the sessions whose figures the docs quote; only runs taken side by
# side compare.
#   bench/peer.sh [ROUNDS] [ITERATIONS]   (defaults 3 and 2: the peer scene's pbf@2)
#     -> a line per run, then the medians and the ratio
# Time: the peer's is its own "Time sum: SimStep" (the steps only: no set-up and no volume
# map build); pbflow's the whole run's wall time (set-up, measures and stats included), so
# the ratio leans the peer's way.
# The peer: SPlisHSPlasH at $commit, cloned into $PEER_SRC (default
# bench_out/peer/SPlisHSPlasH) and built there once (~10 min on two cores). Its GUI library
# needs X11 headers, which this script installs (Debian packages, as scripts/setup.sh does).
# A machine without network brings its own checkout: PEER_SRC=DIR, used as it is.
set -euo pipefail
cd "$(dirname "$0")/.."
rounds="${1:-3}"
iterations="${2:-2}"
[[ "$rounds" =~ ^[1-9][0-9]*$ && "$iterations" =~ ^[1-9][0-9]*$ ]] ||
  { echo "peer.sh: ROUNDS and ITERATIONS must be positive whole numbers (got '$rounds', '$iterations')" >&2; exit 2; }
commit=c5a063ddd33d0172ce951f412fec769929ff57ee
src="${PEER_SRC:-bench_out/peer/SPlisHSPlasH}"
sim="$src/bin/SPHSimulator"
[ -x build/pbflow ] || { echo "peer.sh: build/pbflow is missing: run scripts/setup.sh first" >&2; exit 1; }

if [ ! -x "$sim" ]; then
  if [ ! -d "$src" ]; then
    git clone https://github.com/InteractiveComputerGraphics/SPlisHSPlasH "$src" ||
      { echo "peer.sh: cannot clone SPlisHSPlasH (no network?): set PEER_SRC to a checkout" >&2; exit 1; }
    git -C "$src" checkout -q "$commit"
  fi
  scripts/install-packages.sh libxrandr-dev libxinerama-dev libxcursor-dev libxi-dev libgl-dev
  cmake -S "$src" -B "$src/build" -DCMAKE_BUILD_TYPE=Release -DUSE_PYTHON_BINDINGS=OFF
  cmake --build "$src/build" --target SPHSimulator -j "$(nproc)"
fi
# The scene names its tank's mesh relative to itself: it goes beside the peer's own scenes.
scene="$src/data/Scenes/peer_dam_break_pbf$iterations.json"
sed "s/\"minIterations\": 2, \"maxIterations\": 2/\"minIterations\": $iterations, \"maxIterations\": $iterations/" \
  bench/peer/peer_dam_break_pbf.json > "$scene"
grep -q "\"maxIterations\": $iterations," "$scene" || { echo "peer.sh: could not set the peer's iterations" >&2; exit 1; }

out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
peer_run() {  # -> seconds of SimStep
  OMP_NUM_THREADS=2 "$sim" --no-gui --output-dir "$out/peer" "$scene" > "$out/peer.log"
  awk '/^Time sum: SimStep:/ { printf "%.2f", $4 / 1000 }' "$out/peer.log"
}
pbflow_run() {  # -> "wall-seconds mean-compression particle-steps" (from its summary line)
  build/pbflow run bench/scenes/peer_dam_break.json --iterations "$iterations" --no-render --out "$out/pbflow" 2>/dev/null |
    sed -n 's/^particles \([0-9]*\), steps \([0-9]*\), wall \([0-9.]*\) s,.*mean compression \([0-9.e-]*\),.*/\3 \4 \1*\2/p'
}
peer_run > /dev/null  # not counted: the first run also builds the tank's volume map (cached on disk)
peer=() ours=()
for ((r = 1; r <= rounds; ++r)); do
  p=$(peer_run)
  read -r w c work < <(pbflow_run)
  [ -n "$p" ] && [ -n "$w" ] || { echo "peer.sh: a run printed no time (see $out)" >&2; trap - EXIT; exit 1; }
  printf 'round %d: SPlisHSPlasH PBF %s s (steps), pbflow %.2f s (wall), mean compression %.4f %%\n' \
    "$r" "$p" "$w" "$(awk -v c="$c" 'BEGIN { print 100 * c }')"
  peer+=("$p") ours+=("$w")
done
median() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
mp=$(median "${peer[@]}") mo=$(median "${ours[@]}")
# Both run the same particles and steps (the scenes match: 6859 particles, 500 steps).
awk -v p="$mp" -v o="$mo" -v n="$((work))" 'BEGIN {
  printf "medians: SPlisHSPlasH %.2f s (%.2f M particle-steps/s), pbflow %.2f s (%.2f M): pbflow %.2fx the peer\n",
         p, n / p / 1e6, o, n / o / 1e6, p / o }'
