#!/usr/bin/env bash
# The measurements a lent GPU is for, in one sitting, into OUT (default bench_out/gpu):
# the Vulkan devices; drawing beside the solver for the default run at 720p and 1080p and for
# ~1M particles at 1080p (bench/render.sh, GL timer queries); the cost model up to 4M
# particles (pbflow bench --scaling); the iterations-or-substeps study at 16k and 49k; and what a
# solid's terms cost a step at 16k (the dam break alone, past a box, into the cup's mesh and the
# same water without the cup or with a mesh out of its reach, the mixer's paddle in its mesh
# bowl); and `pbflow serve` at 1080p and 60 fps at a row of counts (bench/serve.py).
#
#   bench/gpu.sh [OUT [PART...]]   PART: render, scaling, pareto, solids, serve (default all)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-bench_out/gpu}
shift || true
parts=${*:-render scaling pareto solids serve}
for part in $parts; do
  case $part in
    render | scaling | pareto | solids | serve) ;;
    *) echo "bench/gpu.sh: no part named $part (render, scaling, pareto, solids, serve)" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"
build/pbflow devices > "$out/devices.txt"

render() {
  build/pbflow run bench/scenes/dam_break_1m.json --frames 2 --width 1920 --height 1080 --verbose \
    --out "$out/run_1m" > "$out/run_1m.txt" 2>&1
  bench/render.sh -f 16 -r "1280x720 1920x1080" -y "fluid particles" > "$out/render.md"
  bench/render.sh -s bench/scenes/dam_break_1m.json -f 8 -r 1920x1080 -y "fluid particles" >> "$out/render.md"
}
scaling() { build/pbflow bench --scaling --budget-minutes 1.5 --out "$out/scaling"; }
pareto() {
  build/pbflow bench --counts 16000,49000 --iterations 1,2,3,4 --substeps 2,4 --seconds 1.5 --scenes dam_break \
    --out "$out/pareto"
}
solids() {
  for scene in dam_break dam_obstacle cup bench/scenes/cup_bare.json bench/scenes/cup_far.json mixer; do
    build/pbflow bench --scaling --scenes "$scene" --counts 16000 --seconds 1 --no-charts \
      --out "$out/solids_$(basename "$scene" .json)"
  done
}
serve() {
  bench/serve.py --parts real_time --fps 60 --size 1920x1080 --spacings 0.02,0.0137,0.01,0.007,0.005 \
    --seconds 6 --out "$out/serve.md"
}
for part in $parts; do "$part"; done
