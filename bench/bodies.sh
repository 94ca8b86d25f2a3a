#!/usr/bin/env bash
# What bodies cost a step: the `floating` scene (6 400 particles, three blocks) without them, with
# the blocks as obstacles standing where they float, the same moving (a 1 mm oscillation: every
# moving solid's cost, its images tested again each pass), the middle block alone as a body, and
# the three as bodies, alternated in one sitting on one device; each run's mean step_ms over
# frames 1-60 (GPU timestamps on a GPU), the medians.
#   bench/bodies.sh DEVICE ROUNDS      (DEVICE: cpu, or a GPU's index or name as --device takes it)
set -euo pipefail
device=$1 rounds=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
boxes() {  # the three blocks as obstacles, each with "$1" added
  echo "obstacles=[{\"type\":\"box\",\"min\":[0.08,0.17,0.11],\"max\":[0.2,0.23,0.21]$1},{\"type\":\"box\",\"min\":[0.34,0.15,0.11],\"max\":[0.46,0.21,0.21]$1},{\"type\":\"box\",\"min\":[0.6,0.02,0.11],\"max\":[0.72,0.08,0.21]$1}]"
}
motion=',"motion":{"type":"oscillate","axis":[0,1,0],"amplitude":0.001,"period":10}'
one='bodies=[{"type":"box","min":[0.34,0.28,0.11],"max":[0.46,0.34,0.21],"density":700,"rotation":[0,0,10]}]'
for _ in $(seq "$rounds"); do
  for which in none standing moving one bodies; do
    case $which in
      none) extra=(--param 'bodies=[]') ;;
      standing) extra=(--param 'bodies=[]' --param "$(boxes '')") ;;
      moving) extra=(--param 'bodies=[]' --param "$(boxes "$motion")") ;;
      one) extra=(--param "$one") ;;
      bodies) extra=() ;;
    esac
    build/pbflow run floating --device "$device" --no-render --quiet --frames 61 --out "$dir/$which" "${extra[@]}"
    echo "$which $(python3 -c "import csv,sys; r=list(csv.DictReader(open(sys.argv[1])))[1:]; print(sum(float(x['step_ms']) for x in r)/len(r))" "$dir/$which/stats.csv")"
  done
done | tee "$dir/times" >&2
python3 - "$dir/times" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
med = {w: statistics.median(float(t) for k, t in rows if k == w) for w in ("none", "standing", "moving", "one", "bodies")}
for w in med:
    print(f"| {w} | {med[w]:.2f} | {med[w] / med['none']:.2f}x |")
print(f"bodies against the same boxes standing: {med['bodies'] / med['standing']:.2f}x, moving: {med['bodies'] / med['moving']:.2f}x")
PY
