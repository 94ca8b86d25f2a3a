#!/usr/bin/env bash
# Sweeps the LDC strength K at 1 iteration on dam_break and hydrostatic (2 s each) and
# prints a markdown table: time-averaged mean compression, worst max compression, and
# the max speed at the end of the hydrostatic run (a tank at rest should not move).
# Usage: bench/ldc_k_sweep.sh [K ...]   (pbflow built in build/)
set -euo pipefail
cd "$(dirname "$0")/.."
ks=("$@")
((${#ks[@]})) || ks=(0 100 300 1000 3000 10000)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
summary() {  # stats.csv -> "time-avg mean compression, max of max compression, last max speed"
  awk -F, 'NR>1 {m+=$3; n++; if ($4>w) w=$4; v=$6} END {printf "%.5f | %.4f | %.3f", m/n, w, v}' "$1"
}
echo "| K (1/s^2) | dam_break mean c | dam_break max c | dam_break end speed | hydrostatic mean c | hydrostatic max c | hydrostatic end speed |"
echo "|---|---|---|---|---|---|---|"
for k in "${ks[@]}"; do
  method=ldc; [ "$k" = 0 ] && method=pbf
  for scene in dam_break hydrostatic; do
    build/pbflow run "$scene" --no-render --quiet --frames 121 --method "$method" --iterations 1 \
      --param solver.ldc_k="$k" --out "$out/$scene"
  done
  echo "| $k$([ "$k" = 0 ] && echo ' (pbf)') | $(summary "$out/dam_break/stats.csv") | $(summary "$out/hydrostatic/stats.csv") |"
done
