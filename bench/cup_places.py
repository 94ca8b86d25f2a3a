#!/usr/bin/env python3
"""Water at rest beside two turned meshes standing in the settled tank: the cup
(scenes/meshes/cup.obj: 48 segments, a round wall 0.02 thick) and a square glass (the cup's
section turned in 4 segments, its radii x sqrt 2: inside 0.16 m across, walls a spacing thick).
Writes the glass's OBJ and each scene under OUT, runs them (`--export ply`) and prints a Markdown
row per place inside each (its floor, wall, the bottom edge where they meet, the wall within h
of the rim; the glass's vertical edges and corners where two walls meet): particles, median deviation from the
interior at the same depth, 1st and 99th percentiles, the median and 99th percentile of
|deviation| (issue 65's bars), median and largest speed.
  bench/cup_places.py PBFLOW OUT [SECONDS] [-- extra pbflow arguments, e.g. --device cpu]"""
import math
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts"))
from boundary import PLACE_HEADER, deviation_and_speed, place_row, read_ply, script_arguments  # noqa: E402
from make_meshes import CUP_SECTION, lathe, write_obj  # noqa: E402

SPACING = 0.02
H = 2 * SPACING
CENTRE = (0.3, 0.3)  # x, z of the solid's axis, standing on the floor
INNER, FLOOR, TOP = 0.08, 0.02, 0.15  # the cup's inner radius, its floor's top, its rim (m)


def solids(repository):
    """(name, OBJ path, segments, scale of the radii) of each solid measured."""
    return [("cup", os.path.join(repository, "scenes", "meshes", "cup.obj"), 48, 1.0),
            ("square glass", "glass.obj", 4, math.sqrt(2))]


def wall_gaps(x, z, segments, scale):
    """Each wall face's distance in front of (x, z), inside: its inner radius less the
    particle's reach along the face's normal (a turned polygon's faces lie between its
    vertices, at cos(pi / segments) of their radius)."""
    dx, dz = x - CENTRE[0], z - CENTRE[1]
    inner = INNER * scale * math.cos(math.pi / segments)
    gaps = []
    for s in range(segments):
        a = 2 * math.pi * (s + 0.5) / segments
        gaps.append(inner - (dx * math.cos(a) - dz * math.sin(a)))
    return sorted(gaps)


def place(p, segments, scale):
    """Where p stands inside the solid, or None (outside it, or not within h of it)."""
    gaps = wall_gaps(p["x"], p["z"], segments, scale)
    if gaps[0] < 0 or p["y"] < FLOOR or p["y"] > TOP:
        return None
    walls = 1 if segments > 8 else sum(g < H for g in gaps)  # a round wall is one face
    walls = walls if gaps[0] < H else 0
    if p["y"] - FLOOR < H:
        return {0: "floor", 1: "bottom edge"}.get(walls, "corner")
    if TOP - p["y"] < H and walls:
        return "wall by the rim"
    return {0: None, 1: "wall"}.get(walls, "vertical edge")


def interior_layers(particles, segments, scale):
    """The median density of each spacing-high layer of particles 2 h from the walls and the
    solid (the solid's turned section, by its bounding cylinder) and 2 h below the surface."""
    top = max(p["y"] for p in particles)
    layers = {}
    for p in particles:
        walls = min(p["x"], 0.6 - p["x"], p["z"], 0.6 - p["z"])
        r = math.hypot(p["x"] - CENTRE[0], p["z"] - CENTRE[1])
        clear = r > 0.1 * scale + 2 * H or p["y"] > TOP + 2 * H
        if walls > 2 * H and clear and p["y"] < top - 2 * H:
            layers.setdefault(int(p["y"] / SPACING), []).append(p["density"])
    return {k: statistics.median(v) for k, v in layers.items()}


def rows(run, frame, segments, scale):
    ply = sorted(os.listdir(os.path.join(run, "particles")))[frame]
    particles = read_ply(os.path.join(run, "particles", ply))
    interior = interior_layers(particles, segments, scale)
    groups = {}
    for p in particles:
        where = place(p, segments, scale)
        if where is None:
            continue
        groups.setdefault(where, []).append(deviation_and_speed(p, interior, SPACING))
    for where, v in sorted(groups.items()):
        yield place_row(where, v)


def run(pbflow, out, name, obj, frames, extra):
    scene = ('{"domain": {"min": [0, 0, 0], "max": [0.6, 0.6, 0.6]}, "particle_spacing": %g, '
             '"fluid_blocks": [{"min": [0, 0, 0], "max": [0.6, 0.4, 0.6]}], "settle": true, '
             '"obstacles": [{"type": "mesh", "file": "%s", "position": [%g, 0, %g]}]}'
             % (SPACING, obj, CENTRE[0], CENTRE[1]))
    path = os.path.join(out, name.replace(" ", "_") + ".json")
    with open(path, "w") as f:
        f.write(scene)
    done = subprocess.run([pbflow, "run", path, "--no-render", "--export", "ply", "--frames", str(frames),
                           "--out", path[:-len(".json")]] + extra, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(done.stderr)
    return path[:-len(".json")]


def main():
    pbflow, out, seconds, extra = script_arguments(__doc__)
    write_obj(os.path.join(out, "glass.obj"), *lathe([(r * math.sqrt(2), y) for r, y in CUP_SECTION], 4))
    frames = int(round(seconds * 60)) + 1
    repository = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    for name, obj, segments, scale in solids(repository):
        directory = run(pbflow, out, name, os.path.abspath(os.path.join(out, obj)), frames, extra)
        print("\n%s, %g s after the settle\n" % (name, seconds))
        print(PLACE_HEADER)
        for row in rows(directory, frames - 1, segments, scale):
            print(row)


if __name__ == "__main__":
    main()
