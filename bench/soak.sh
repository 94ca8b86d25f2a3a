#!/usr/bin/env bash
# Soak: 20 000 steps of a small dam break must end healthy (exit 0: the divergence watch
# saw no NaN, runaway or escaped particle) with the same memory as a run a tenth as long
# (no growth on the host or, under lavapipe, the device, whose memory is host memory).
#   bench/soak.sh [DEVICE]     -> prints max resident memory of both runs and their verdict
# Needs /usr/bin/time (Debian package time).
set -euo pipefail
cd "$(dirname "$0")/.."
device="${1:-auto}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
run() {  # frames -> max RSS in KiB
  /usr/bin/time -f "%M" -o "$out/rss" build/pbflow run dam_break --device "$device" --no-render --quiet \
    --param particle_spacing=0.05 --frames "$1" --out "$out/run$1" >/dev/null
  cat "$out/rss"
}
short=$(run 1001)
long=$(run 10001)
rows=$(($(wc -l < "$out/run10001/stats.csv") - 1))
echo "steps 20000: exit 0, $rows stats rows; max RSS ${long} KiB vs ${short} KiB for 2000 steps"
if (( rows != 10001 )); then echo "soak: missing rows"; exit 1; fi
if (( long > short + short / 20 )); then echo "soak: memory grew by more than 5 %"; exit 1; fi
echo "soak: ok"
