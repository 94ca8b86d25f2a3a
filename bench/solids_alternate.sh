#!/usr/bin/env bash
# Builds of pbflow alternated over the scenes that price a solid (bench/gpu.sh's solids part),
# ROUNDS rounds in one sitting: each run's GPU ms a step and per pass group at 16k particles
# over 1 s (pbflow bench --scaling), a line each. A build is a path to its pbflow binary, or a
# command (a bundle's wrapper with its loader), quoted.
#
#   bench/solids_alternate.sh ROUNDS PBFLOW... > rows.txt
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=$1
shift
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
for round in $(seq "$rounds"); do
  for build in "$@"; do
    for scene in cup bench/scenes/cup_bare.json bench/scenes/cup_far.json dam_obstacle mixer; do
      $build bench --scaling --scenes "$scene" --counts 16000 --seconds 1 --no-charts --out "$dir/run" > /dev/null
      python3 - "$dir/run/scaling.csv" "$round $(basename "${build##* }") $(basename "$scene" .json)" <<'PY'
import csv, sys
row = next(csv.DictReader(open(sys.argv[1])))
groups = ["step", "lists", "constraints", "viscosity", "predict", "grid", "coarse"]
print(sys.argv[2], " ".join(f"{g}={float(row[g + '_ms']):.4f}" for g in groups))
PY
      rm -rf "$dir/run"
    done
  done
done
