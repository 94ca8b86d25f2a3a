#!/usr/bin/env bash
# Soundness matrix: every scene x setting at the scenes' own step, full size. A row per run:
# the exit status (3: the divergence watch stopped it), the energy gain (largest rise of
# KE + PE over its value at frame 0, % of the initial potential energy; a sound solver has
# 0), the rise over the running minimum (energy stored in compression and given back), the
# time-averaged and the largest mean compression (a column squeezed and released shows in
# the second) and the max speed at the end, all from DIR/stats.csv.
#
#   bench/soundness.sh [-s "dam_break drop"] [-m "pbf@1 ldc@1"] [-t SECONDS] [-p PARAM]... [-k DIR] > table.md
#
# Defaults: the five built-in scenes, pbf@1-4 and ldc@1-2, 1.5 s (hydrostatic 2 s, after its settle).
# -p passes a --param to every run (e.g. -p solver.substeps=8, -p particle_spacing=0.01).
# -k keeps every run's directory (stats.csv, run.json, the log) under DIR.
set -euo pipefail
cd "$(dirname "$0")/.."
scenes="dam_break drop double_dam_break dam_obstacle hydrostatic"
settings="pbf@1 pbf@2 pbf@3 pbf@4 ldc@1 ldc@2"
seconds=
params=()
keep=
while getopts "s:m:t:p:k:" opt; do
  case $opt in
    s) scenes=$OPTARG ;;
    m) settings=$OPTARG ;;
    t) seconds=$OPTARG ;;
    p) params+=(--param "$OPTARG") ;;
    k) keep=$OPTARG ;;
    *) echo "usage: $0 [-s scenes] [-m settings] [-t seconds] [-p param]... [-k dir]" >&2; exit 2 ;;
  esac
done
if [[ -n $keep ]]; then
  mkdir -p "$keep"
  out=$keep
else
  out="$(mktemp -d)"
  trap 'rm -rf "$out"' EXIT
fi

echo "| scene | setting | particles | exit | energy gain | rise over running min | mean compression | largest mean compression | max speed at end | wall s |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for scene in $scenes; do
  t=${seconds:-1.5}
  [[ -z $seconds && $scene == hydrostatic ]] && t=2
  frames=$(awk -v t="$t" 'BEGIN { printf "%d", t * 60 + 1.5 }')  # every built-in scene runs at 60 fps
  for setting in $settings; do
    method=${setting%@*} iterations=${setting#*@}
    dir="$out/${scene}_${method}${iterations}"
    start=$(date +%s.%N)
    status=0
    build/pbflow run "$scene" --method "$method" --iterations "$iterations" --frames "$frames" \
      --no-render --out "$dir" "${params[@]}" >"$dir.log" 2>&1 || status=$?
    wall=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.0f", b - a }')
    if [[ ! -s $dir/stats.csv ]]; then
      echo "| $scene | $setting | - | $status | $(grep -m1 "error" "$dir.log" | head -c 100) | | | | | $wall |"
      continue
    fi
    particles=$(grep -o -m1 '[0-9]* particles,' "$dir.log" | grep -o '^[0-9]*' || echo "?")
    awk -F, -v scene="$scene" -v setting="$setting" -v status="$status" -v wall="$wall" -v n="$particles" '
      NR == 1 { for (c = 1; c <= NF; ++c) col[$c] = c; next }
      {
        e = $col["kinetic_energy"] + $col["potential_energy"]
        if (NR == 2) { e0 = e; pe0 = $col["potential_energy"]; lo = e }
        if (e < lo) lo = e
        if (e - e0 > gain) gain = e - e0
        if (e - lo > rise) rise = e - lo
        compression += $col["mean_compression"]; rows++
        if ($col["mean_compression"] > peak) peak = $col["mean_compression"]
        speed = $col["max_speed"]
      }
      END {
        printf "| %s | %s | %s | %s | %.2f %% | %.1f %% | %.1f %% | %.1f %% | %.2f m/s | %s |\n", scene, setting, n,
               status, 100 * gain / pe0, 100 * rise / pe0, 100 * compression / rows, 100 * peak, speed, wall
      }' "$dir/stats.csv"
  done
done
