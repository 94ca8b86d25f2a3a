#!/usr/bin/env python3
"""Water at rest in a box-shaped mesh tank (a 0.44 m box as domain.mesh, water 0.3 m deep) against
the same box as the tank's own walls: how the fluid reads at the mesh's faces, edges and corners
(its concave creases) after the settle and `seconds` later. Writes the box's OBJ and the two
scenes under OUT, runs both (`--export ply`) and prints a Markdown row per place: particles,
median deviation from the interior at the same depth, 1st and 99th percentiles, the median and
99th percentile of |deviation|, median and largest speed.
  bench/mesh_tank.py PBFLOW OUT [SECONDS] [-- extra pbflow arguments, e.g. --device cpu]"""
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from boundary import PLACE_HEADER, deviation_and_speed, place_row, read_ply, script_arguments  # noqa: E402

LO, HI, SPACING = 0.02, 0.46, 0.02
H = 2 * SPACING


def write_box(path):
    corners = [(x, y, z) for z in (LO, HI) for y in (LO, HI) for x in (LO, HI)]  # bit 0 x, bit 1 y, bit 2 z
    faces = [(0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3), (0, 2, 3, 1), (4, 5, 7, 6)]  # outward
    with open(path, "w") as f:
        f.writelines("v %g %g %g\n" % c for c in corners)
        for a, b, c, d in faces:
            f.write("f %d %d %d\nf %d %d %d\n" % (a + 1, b + 1, c + 1, a + 1, c + 1, d + 1))


def scene(mesh):
    domain = {"min": [0, 0, 0], "max": [0.48, 0.48, 0.48], "mesh": {"file": "box.obj"}} if mesh else \
        {"min": [LO] * 3, "max": [HI] * 3}
    block = [0, 0, 0] if mesh else [LO] * 3
    top = [0.48, 0.32, 0.48] if mesh else [HI, 0.32, HI]
    return ('{"domain": %s, "particle_spacing": %g, "fluid_blocks": [{"min": %s, "max": %s}], "settle": true}'
            % (str(domain).replace("'", '"'), SPACING, block, top))


def rows(run, frame):
    ply = sorted(os.listdir(os.path.join(run, "particles")))[frame]
    ps = read_ply(os.path.join(run, "particles", ply))
    top = max(p["y"] for p in ps)
    gaps = lambda p: [p["x"] - LO, HI - p["x"], p["y"] - LO, p["z"] - LO, HI - p["z"]]  # noqa: E731
    layers = {}
    for p in ps:
        if min(gaps(p)) > 2 * H and p["y"] < top - 2 * H:
            layers.setdefault(int(p["y"] / SPACING), []).append(p["density"])
    interior = {k: statistics.median(v) for k, v in layers.items()}
    groups = {}
    for p in ps:
        near = [k for k, g in enumerate(gaps(p)) if g < H]
        if not near or p["y"] > top - 2 * H:
            continue
        walls = len(near) - (2 in near)
        place = {0: "floor", 1: "wall", 2: "vertical edge"}[min(walls, 2)] if 2 not in near or walls == 0 else \
            {1: "bottom edge", 2: "bottom corner"}[min(walls, 2)]
        groups.setdefault(place, []).append(deviation_and_speed(p, interior, SPACING))
    for place, v in sorted(groups.items()):
        yield place_row(place, v)


def main():
    pbflow, out, seconds, extra = script_arguments(__doc__)
    write_box(os.path.join(out, "box.obj"))
    frames = int(round(seconds * 60)) + 1
    for name, mesh in (("mesh", True), ("walls", False)):
        path = os.path.join(out, name + ".json")
        with open(path, "w") as f:
            f.write(scene(mesh))
        subprocess.run([pbflow, "run", path, "--no-render", "--export", "ply", "--frames", str(frames),
                        "--out", os.path.join(out, name)] + extra, check=True, stdout=subprocess.DEVNULL)
        print("\n%s tank, %g s after the settle\n" % (name, seconds))
        print(PLACE_HEADER)
        for row in rows(os.path.join(out, name), frames - 1):
            print(row)


if __name__ == "__main__":
    main()
