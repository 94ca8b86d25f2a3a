#!/usr/bin/env bash
# The CPU peer beside pbflow, in the same minutes: SPlisHSPlasH's PBF (2 OpenMP threads,
# Release build) on its own dam break (bench/peer/peer_dam_break_pbf.json: 6859 particles,
# dt 4 ms, 2 s) and `pbflow run bench/scenes/peer_dam_break.json --no-render`, alternated:
# a shared machine drifts by up to 1.5x from minute to minute, so only runs taken side by
# side compare.
#   bench/peer.sh [ROUNDS] [PBFLOW_ITERATIONS] [PEER_ITERATIONS]   (defaults 3, 3 and 4)
#     -> a line per round, then the medians and the ratio
# Each side has its own iteration count: the fair comparison is at equal accuracy, and each
# side's mean compression is printed beside its time (pbflow's from its summary, the peer's
# from its own densities, exported as VTK and read by bench/peer/compression.py).
# Time: the peer's is its own "Time sum: SimStep" (the steps only: no set-up, volume map or
# export); pbflow's the whole run's wall time (set-up, measures and stats included), so the
# ratio leans the peer's way.
# The peer: SPlisHSPlasH at a pinned commit, built once by bench/peer/build.sh (PEER_SRC=DIR
# names a checkout of its own on a machine without network).
set -euo pipefail
cd "$(dirname "$0")/.."
rounds="${1:-3}" ours_iterations="${2:-3}" peer_iterations="${3:-4}"
for n in "$rounds" "$ours_iterations" "$peer_iterations"; do
  [[ "$n" =~ ^[1-9][0-9]*$ ]] ||
    { echo "peer.sh: ROUNDS and the iteration counts must be positive whole numbers (got '$n')" >&2; exit 2; }
done
[ -x build/pbflow ] || { echo "peer.sh: build/pbflow is missing: run scripts/setup.sh first" >&2; exit 1; }
sim="$(bench/peer/build.sh)"
src="$(dirname "$(dirname "$sim")")"
# The scene names its tank's mesh relative to itself: it goes beside the peer's own scenes,
# with the peer's iterations and its densities exported for its compression.
scene="$src/data/Scenes/peer_dam_break_pbf$peer_iterations.json"
python3 - "$peer_iterations" bench/peer/peer_dam_break_pbf.json "$scene" <<'PY'
import json, sys
iterations, source, target = int(sys.argv[1]), sys.argv[2], sys.argv[3]
scene = json.load(open(source))
c = scene["Configuration"]
c["PBF"].update(minIterations=iterations, maxIterations=iterations)
c.update(enableVTKExport=True, particleAttributes="density", dataExportFPS=25)
json.dump(scene, open(target, "w"), indent=1)
PY
rho0=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["Materials"][0]["density0"])' "$scene")

out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
fail() {  # keeps the logs: the run that failed is the one to read
  trap - EXIT
  echo "peer.sh: $1 (logs in $out)" >&2
  exit 1
}
peer_run() {  # -> "seconds-of-SimStep mean-compression"
  rm -rf "$out/peer"
  OMP_NUM_THREADS=2 "$sim" --no-gui --output-dir "$out/peer" "$scene" > "$out/peer.log" 2>&1 ||
    fail "SPlisHSPlasH failed: $(tail -n 3 "$out/peer.log" | tr '\n' ' ')"
  local seconds compression
  seconds=$(awk '/^Time sum: SimStep:/ { printf "%.2f", $4 / 1000 }' "$out/peer.log")
  compression=$(bench/peer/compression.py "$rho0" $(find "$out/peer" -name 'ParticleData_*.vtk')) ||
    fail "no density from the peer's VTK files"
  echo "$seconds $compression"
}
pbflow_run() {  # -> "wall-seconds mean-compression particle-steps" (from its summary line)
  build/pbflow run bench/scenes/peer_dam_break.json --iterations "$ours_iterations" --no-render --out "$out/pbflow" \
    2> "$out/pbflow.log" |
    sed -n 's/^particles \([0-9]*\), steps \([0-9]*\), wall \([0-9.]*\) s,.*mean compression \([0-9.e-]*\),.*/\3 \4 \1*\2/p'
}
percent() { awk -v c="$1" 'BEGIN { printf "%.3f", 100 * c }'; }
peer_run > /dev/null  # not counted: the first run also builds the tank's volume map (cached on disk)
peer=() ours=()
for ((r = 1; r <= rounds; ++r)); do
  read -r p pc < <(peer_run)
  read -r w c work < <(pbflow_run)
  [ -n "${p:-}" ] && [ -n "${w:-}" ] || fail "a run printed no time"
  printf 'round %d: SPlisHSPlasH pbf@%d %s s (steps), mean compression %s %%; pbflow pbf@%d %.2f s (wall), %s %%\n' \
    "$r" "$peer_iterations" "$p" "$(percent "$pc")" "$ours_iterations" "$w" "$(percent "$c")"
  peer+=("$p") ours+=("$w")
done
median() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
mp=$(median "${peer[@]}") mo=$(median "${ours[@]}")
# Both run the same particles and steps (the scenes match: 6859 particles, 500 steps).
awk -v p="$mp" -v o="$mo" -v n="$((work))" 'BEGIN {
  printf "medians: SPlisHSPlasH %.2f s (%.2f M particle-steps/s), pbflow %.2f s (%.2f M): pbflow %.2fx the peer\n",
         p, n / p / 1e6, o, n / o / 1e6, p / o }'
