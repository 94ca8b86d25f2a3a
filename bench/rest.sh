#!/usr/bin/env bash
# The tank at rest at its own step: `pbflow run hydrostatic` (settled first) for each
# setting, 2 s; a markdown row per setting with the max, median and 99th percentile speed
# at t = 2 s (from the last frame's PLY), the mean compression then, and the energy gain
# (largest rise of KE + PE over frame 0, % of the initial potential energy).
#
#   bench/rest.sh [-m "ldc@1 pbf@1"] > table.md
set -euo pipefail
cd "$(dirname "$0")/.."
settings="ldc@1 ldc@2 pbf@1 pbf@2 pbf@3"
while getopts "m:" opt; do
  case $opt in
    m) settings=$OPTARG ;;
    *) echo "usage: $0 [-m settings]" >&2; exit 2 ;;
  esac
done
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "| setting | max speed | median | 99th percentile | mean compression | energy gain |"
echo "|---|---|---|---|---|---|"
for setting in $settings; do
  method=${setting%@*} iterations=${setting#*@}
  build/pbflow run hydrostatic --method "$method" --iterations "$iterations" --frames 121 --no-render --quiet \
    --export ply --out "$out/$setting"
  python3 - "$setting" "$out/$setting" <<'PY'
import csv, struct, sys
setting, run = sys.argv[1], sys.argv[2]
rows = list(csv.DictReader(open(f"{run}/stats.csv")))
energy = [float(r["kinetic_energy"]) + float(r["potential_energy"]) for r in rows]
gain = max(e - energy[0] for e in energy) / float(rows[0]["potential_energy"])
data = open(f"{run}/particles/frame_{len(rows) - 1:05d}.ply", "rb").read()
body = data[data.index(b"end_header\n") + len(b"end_header\n"):]
speeds = sorted((vx * vx + vy * vy + vz * vz) ** 0.5 for _, _, _, vx, vy, vz, _ in struct.iter_unpack("<7f", body))
pick = lambda q: speeds[min(len(speeds) - 1, int(q * len(speeds)))]
print(f"| {setting} | {speeds[-1]:.3f} m/s | {pick(0.5):.3f} m/s | {pick(0.99):.3f} m/s | "
      f"{100 * float(rows[-1]['mean_compression']):.1f} % | {100 * gain:.2f} % |")
PY
done
