#!/usr/bin/env bash
# The fluid at rest beside solids, pbflow against the CPU peer (SPlisHSPlasH, volume-map
# boundaries), each read by the same yardstick (bench/boundary.py --where): the settled tank
# with a ball and a box standing on its floor (docs/physics.md, "Boundaries"; issue 65's bars).
# pbflow: `hydrostatic` with the two obstacles, pbf@2, 1 s after its settle. The peer, from its
# own lattice (it has no settle), SECONDS later (default 4): DFSPH at 2 iterations and at its
# tolerance (0.01 %, up to 100 iterations), both at its CFL step, and its PBF with 2 iterations
# at pbflow's step (1/120 s) and at its CFL step. The peer's particles weigh what pbflow's do
# (its radius 0.01077 m at pbflow's 0.02 m spacing); a particle it lets out of the tank is
# counted and left out. The peer runs on OpenMP: its rows vary a little from run to run.
#   bench/peer/boundary.sh [SECONDS]   -> a table per run; logs and frames in bench_out/peer/boundary
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds="${1:-4}"
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] ||
  { echo "boundary.sh: SECONDS must be a positive whole number (got '$seconds')" >&2; exit 2; }
[ -x build/pbflow ] || { echo "boundary.sh: build/pbflow is missing: run scripts/setup.sh first" >&2; exit 1; }
sim="$(bench/peer/build.sh)"
export PEER_ROOT="$(dirname "$(dirname "$sim")")"
out="$(realpath -m bench_out/peer/boundary)"
rm -rf "$out" && mkdir -p "$out"
obstacles='[{"type": "sphere", "centre": [0.3, 0.2, 0.3], "radius": 0.1},
            {"type": "box", "min": [0.05, 0, 0.05], "max": [0.15, 0.1, 0.15]}]'

build/pbflow run hydrostatic --no-render --export ply --frames 61 --out "$out/pbflow" \
  --param "obstacles=$obstacles" > "$out/pbflow.log" 2>&1 ||
  { echo "boundary.sh: pbflow failed (see $out/pbflow.log)" >&2; exit 1; }
echo "pbflow, pbf@2, 1 s after the settle:"
bench/boundary.py --where "$out/pbflow" 60

peer() {  # NAME SCENE: the peer's run, its VTK frames in $out/NAME
  OMP_NUM_THREADS=2 "$sim" --no-gui --output-dir "$out/$1" "$2" > "$out/$1.log" 2>&1 ||
    { echo "boundary.sh: the peer failed on $2 (see $out/$1.log)" >&2; exit 1; }
}
bench/peer/boundary_scenes.py fill "$out/pbflow/run.json" "$out"
peer fill "$out/fill.json"
bench/peer/boundary_scenes.py scenes "$out/pbflow/run.json" "$out" "$out/fill/vtk/ParticleData_Fluid_1.vtk" "$seconds"
for variant in dfsph2 dfsph pbf2 pbf2cfl; do
  peer "$variant" "$out/$variant.json"
  bench/peer/vtk_run.py "$out/scene.json" "$out/$variant-run" "$out/$variant"/vtk/*.vtk
  echo
  averages=$(grep -h 'Average number: \(Time step size\|DFSPH - iterations\|PBF - iterations\)' "$out/$variant.log" |
    sed 's/Average number: //' | tr '\n' ';')
  echo "SPlisHSPlasH $variant, $seconds s: $averages"
  bench/boundary.py --where "$out/$variant-run"
done
