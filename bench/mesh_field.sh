#!/usr/bin/env bash
# What a large mesh costs at load: a closed ring of 102 400 triangles (a lathe of
# scripts/make_meshes.py) placed in the dam break, against the same scene without it, timed to
# the run's first line (the scene read, the solver made, before the start's relaxation): the
# difference is reading the mesh and building its distance field (OpenVDB, half a spacing).
# Median of five each, alternated.
#   bench/mesh_field.sh [PBFLOW]   (default build/pbflow)
set -euo pipefail
cd "$(dirname "$0")/.."
python3 - "${1:-build/pbflow}" <<'PY'
import math, os, statistics, subprocess, sys, tempfile, time
sys.path.insert(0, "scripts")
import make_meshes
pbflow, out = sys.argv[1], tempfile.mkdtemp()
ring = [(0.15 + 0.05 * math.cos(2 * math.pi * k / 160), 0.1 + 0.05 * math.sin(2 * math.pi * k / 160)) for k in range(160)]
mesh = os.path.join(out, "ring.obj")
make_meshes.write_obj(mesh, *make_meshes.lathe(ring, 320))
def first_line(*extra):
    began = time.monotonic()
    run = subprocess.Popen([pbflow, "run", "dam_break", "--no-render", "--frames", "1", "--out", os.path.join(out, "run"), *extra],
                           stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True)
    run.stderr.readline()
    seconds = time.monotonic() - began
    run.kill()
    run.wait()
    return seconds
placed = ["--param", '{"type":"mesh","file":"%s","position":[0.9,0,0.2]}' % mesh]
placed[1] = "obstacles=[" + placed[1] + "]"
times = {"without": [], "with": []}
for _ in range(5):
    times["without"].append(first_line())
    times["with"].append(first_line(*placed))
a, b = statistics.median(times["without"]), statistics.median(times["with"])
print(f"| 102 400 triangles | {a:.2f} s | {b:.2f} s | {b - a:.2f} s |")
PY
