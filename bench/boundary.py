#!/usr/bin/env python3
"""How the fluid at rest reads beside each solid, against the interior at the same depth: the
yardstick of a boundary model (a particle beside a wall or an obstacle should read what one
inside reads). For one frame of a run exported as PLY (`pbflow run ... --export ply`):
each particle within a kernel radius (2 spacings) of one solid's surface (a wall, an obstacle) and
of no other is
compared with the median density of the interior particles in its layer (one spacing high;
interior: farther than 2 kernel radii from every solid and below the free surface by as much).
A layer with no interior (the floor's first 2 h) is held to the nearest one that has, whose
density differs by ~0.1 %. Prints a Markdown row per solid: particles, median deviation, 1st and
99th percentiles, and the median and 99th percentile of its size (issue 65's bars); and the
frame's largest speed. With --where, each box's and sphere's particles are split by where they
stand (a box: above its top face, under its bottom face, beside a side face, round an edge or
corner; a sphere: over or under its caps within 45 degrees of the vertical, beside its upper or
lower side) and their distance from it in half spacings.
  bench/boundary.py [--where] RUN_DIR [FRAME]     (FRAME: default the last)"""
import glob
import json
import math
import os
import struct
import sys


def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().split("\n")
    n = next(int(line.split()[2]) for line in header if line.startswith("element vertex"))
    properties = [line.split()[1:3] for line in header if line.startswith("property ")]
    names = [name for _, name in properties]
    record = "<" + "".join("I" if kind == "uint" else "f" for kind, _ in properties)  # an id is a uint
    values = [v for k in range(n) for v in struct.unpack_from(record, data, end + k * struct.calcsize(record))]
    return [dict(zip(names, values[k * len(names):(k + 1) * len(names)])) for k in range(n)]


def script_arguments(doc):
    """PBFLOW OUT [SECONDS] [-- extra pbflow arguments] of the scripts that run scenes and count
    places (mesh_tank.py, cup_places.py): (pbflow, out, seconds, extra); exits with doc if short."""
    if len(sys.argv) < 3:
        sys.exit(doc)
    seconds = float(sys.argv[3]) if len(sys.argv) > 3 and sys.argv[3] != "--" else 1.0
    extra = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    os.makedirs(sys.argv[2], exist_ok=True)
    return sys.argv[1], sys.argv[2], seconds, extra


def nearest_layer(layers, k):
    """The value of the layer in `layers` (index: height in spacings) nearest layer k."""
    return layers[min(layers, key=lambda j: abs(j - k))]


def deviation_and_speed(p, interior, spacing):
    """A particle's density against its nearest interior layer's (in %) and its speed."""
    rho = nearest_layer(interior, int(p["y"] / spacing))
    return 100 * (p["density"] / rho - 1), math.sqrt(p["vx"] ** 2 + p["vy"] ** 2 + p["vz"] ** 2)


PLACE_HEADER = ("| place | particles | median | 1st pct | 99th pct | median abs | 99th pct abs | median speed | largest |\n"
                "|---|---|---|---|---|---|---|---|---|")


def place_row(place, values):
    """A Markdown row of PLACE_HEADER from (deviation in %, speed) pairs."""
    d, s = sorted(x for x, _ in values), sorted(x for _, x in values)
    size = sorted(abs(x) for x in d)
    return "| %s | %d | %+.2f %% | %+.2f %% | %+.2f %% | %.2f %% | %.2f %% | %.4f | %.4f |" % (
        place, len(values), percentile(d, 0.5), percentile(d, 0.01), percentile(d, 0.99),
        percentile(size, 0.5), percentile(size, 0.99), percentile(s, 0.5), s[-1])


def distance_to(solid, p):
    """Distance from p to a solid's surface: a box {min, max} or a sphere {centre, radius}."""
    if solid.get("type") == "sphere":
        return abs(math.dist(p, solid["centre"]) - solid["radius"])
    lo, hi = solid["min"], solid["max"]
    outside = [max(lo[a] - p[a], 0.0, p[a] - hi[a]) for a in range(3)]
    if any(outside):
        return math.hypot(*outside)
    return min(min(p[a] - lo[a], hi[a] - p[a]) for a in range(3))


def percentile(values, q):
    s = sorted(values)
    return s[min(len(s) - 1, max(0, int(round(q * (len(s) - 1)))))] if s else float("nan")


def place(solid, p):
    """Where p stands beside a solid: a box's top face, bottom face, side face or edges; a
    sphere's cap within 45 degrees of the top or the bottom, or its upper or lower side."""
    if solid.get("type") == "sphere":
        c = solid["centre"]
        up = (p[1] - c[1]) / max(math.dist(p, c), 1e-12)
        return ("over its top cap" if up > math.sqrt(0.5) else "beside its upper side" if up > 0 else
                "beside its lower side" if up > -math.sqrt(0.5) else "under its bottom cap")
    out = [a for a in range(3) if p[a] < solid["min"][a] or p[a] > solid["max"][a]]
    if out == [1]:
        return "above its top face" if p[1] > solid["max"][1] else "under its bottom face"
    return "beside a side face" if len(out) == 1 else "round an edge or corner"


def print_places(solid, rows, spacing):
    """rows: (position, deviation) of one solid's particles; a row per place and distance."""
    groups = {}
    for p, deviation in rows:
        distance = round(distance_to(solid, p) / spacing * 2) / 2
        groups.setdefault((place(solid, p), distance), []).append(deviation)
    print("| where | distance | particles | median | least |")
    print("|---|---|---|---|---|")
    for (where, distance), v in sorted(groups.items()):
        print(f"| {where} | {distance:g} | {len(v)} | {100 * percentile(v, 0.5):+.2f} % | {100 * min(v):+.2f} % |")


def main(args):
    where = "--where" in args
    args = [a for a in args if a != "--where"]
    if not args:
        raise SystemExit(__doc__)
    run = args[0]
    manifest = json.load(open(os.path.join(run, "run.json")))
    scene = manifest["scene"]
    spacing = scene["particle_spacing"]
    h = 2 * spacing  # solver.kernel_ratio's default
    lo, hi = scene["domain"]["min"], scene["domain"]["max"]
    walls = [{"type": "box", "min": lo, "max": hi}]  # the tank, seen from inside
    obstacles = scene.get("obstacles", [])
    frames = sorted(glob.glob(os.path.join(run, "particles", "frame_*.ply")))
    path = frames[-1] if len(args) < 2 else os.path.join(run, "particles", f"frame_{int(args[1]):05d}.ply")
    particles = read_ply(path)
    top = max(p["y"] for p in particles)
    layer = lambda p: int(p["y"] / spacing)
    near = lambda solid, p: distance_to(solid, (p["x"], p["y"], p["z"])) < h
    interior = {}
    for p in particles:
        if all(not near(s, p) and distance_to(s, (p["x"], p["y"], p["z"])) >= 2 * h for s in walls + obstacles) and \
                p["y"] < top - 2 * h:
            interior.setdefault(layer(p), []).append(p["density"])
    medians = {k: percentile(v, 0.5) for k, v in interior.items()}
    # A layer with no interior (the floor's first 2 h, every solid's reach) takes its nearest
    # interior layer's density: the interior's layers differ by ~0.1 % over 2 h.
    reference = {k: nearest_layer(medians, k) for k in range(max(interior) + 1)}
    print(f"{os.path.basename(path)}: largest speed {max(math.sqrt(p['vx']**2 + p['vy']**2 + p['vz']**2) for p in particles):.3f} m/s")
    print("| beside | particles | median deviation | 1st percentile | 99th percentile | median abs | 99th pct abs |")
    print("|---|---|---|---|---|---|---|")
    solids = [("the tank's walls", walls[0])] + [(f"obstacle {k} ({o.get('type')})", o) for k, o in enumerate(obstacles)]
    beside = {}
    for name, solid in solids:  # a particle beside this solid alone, below the surface's layers
        rows = [((p["x"], p["y"], p["z"]), p["density"] / reference[layer(p)] - 1) for p in particles
                if near(solid, p) and not any(near(o, p) for _, o in solids if o is not solid)
                and layer(p) in reference and p["y"] < top - 2 * h]
        deviation = [d for _, d in rows]
        size = [abs(d) for d in deviation]
        beside[name] = rows
        print(f"| {name} | {len(deviation)} | {100 * percentile(deviation, 0.5):+.2f} % | "
              f"{100 * percentile(deviation, 0.01):+.2f} % | {100 * percentile(deviation, 0.99):+.2f} % | "
              f"{100 * percentile(size, 0.5):.2f} % | {100 * percentile(size, 0.99):.2f} % |")
    for name, solid in solids[1:] if where else []:
        if solid.get("type", "box") in ("box", "sphere"):
            print(f"\n{name}:")
            print_places(solid, beside[name], spacing)


if __name__ == "__main__":
    main(sys.argv[1:])
