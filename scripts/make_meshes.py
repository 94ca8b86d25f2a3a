#!/usr/bin/env python3
"""Writes the meshes the scenes use (scenes/meshes/*.obj): closed triangle meshes, in metres.
Usage: scripts/make_meshes.py [OUT_DIR]

- rock.obj: an icosphere of radius 0.1 subdivided three times, each vertex's radius varied
  by a fixed pseudo-random +-15 %.
- ball.obj: the same icosphere unvaried (the analytic sphere's twin, for tests).
- cup.obj: a cup turned about y: outer radius 0.1, wall 0.02 thick, 0.15 tall, floor 0.02.
- bowl.obj: a bowl's inside, for a domain's mesh (the fluid inside it): a hemisphere of radius
  0.22 whose lowest point is 0.02 above y = 0, walls straight up from its rim to y = 0.5, a lid.
- paddle.obj: a paddle's outline (a blade 0.3 wide and 0.2 tall, a shaft 0.03 wide up to 0.45)
  extruded 0.04 thick along z, centred on z = 0.
- hull.obj: a boat's hull: the icosphere stretched to 0.6 long, 0.24 wide, its lower half 0.1
  deep and its upper half flattened to a deck 0.02 above the waterline (y = 0).
"""
import math
import os
import random
import sys


# The cup's section, counter-clockwise in (r, y): the floor's underside out to the outer wall,
# up it, over the rim, down the inner wall to the floor's top (bench/cup_places.py turns it too).
CUP_SECTION = [(0.0, 0.0), (0.1, 0.0), (0.1, 0.15), (0.08, 0.15), (0.08, 0.02), (0.0, 0.02)]


def icosphere(levels):
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
         (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    v = [tuple(c / math.sqrt(sum(x * x for x in p)) for c in p) for p in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(levels):
        middle = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in middle:
                p = [(x + y) / 2 for x, y in zip(v[a], v[b])]
                n = math.sqrt(sum(x * x for x in p))
                v.append(tuple(x / n for x in p))
                middle[key] = len(v) - 1
            return middle[key]

        f = [g for a, b, c in f for g in
             ((a, mid(a, b), mid(c, a)), (b, mid(b, c), mid(a, b)), (c, mid(c, a), mid(b, c)),
              (mid(a, b), mid(b, c), mid(c, a)))]
    return v, f


def lathe(profile, segments):
    """A closed solid of revolution about y from a closed (r, y) loop, counter-clockwise."""
    v, f, index = [], [], {}
    for s in range(segments):
        a = 2 * math.pi * s / segments
        for k, (r, y) in enumerate(profile):
            if r == 0 and (0, k) in index:  # a point on the axis is one vertex
                index[s, k] = index[0, k]
                continue
            index[s, k] = len(v)
            v.append((r * math.cos(a), y, -r * math.sin(a)))
    n = len(profile)
    for s in range(segments):
        s2 = (s + 1) % segments
        for k in range(n):
            k2 = (k + 1) % n
            quad = [(index[s, k], index[s2, k], index[s2, k2]), (index[s, k], index[s2, k2], index[s, k2])]
            f += [t for t in quad if len(set(t)) == 3]
    return v, f


def extrude(outline, centre, depth):
    """A closed prism: a counter-clockwise outline in (x, y), star-shaped about `centre`,
    extruded from z = -depth / 2 to depth / 2, its caps fanned from the centre."""
    n = len(outline)
    v = [(x, y, z) for z in (-depth / 2, depth / 2) for x, y in outline] + \
        [(centre[0], centre[1], -depth / 2), (centre[0], centre[1], depth / 2)]
    back, front = 2 * n, 2 * n + 1
    f = []
    for k in range(n):
        k2 = (k + 1) % n
        f += [(k, k2, n + k2), (k, n + k2, n + k)]  # the side, facing out
        f += [(back, k2, k), (front, n + k, n + k2)]  # the caps: -z seen from behind, +z from the front
    return v, f


def write_obj(path, v, f):
    with open(path, "w") as out:
        out.write("# made by scripts/make_meshes.py\n")
        out.writelines("v %.6f %.6f %.6f\n" % p for p in v)
        out.writelines("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in f)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "scenes", "meshes")
    os.makedirs(out, exist_ok=True)
    v, f = icosphere(3)
    write_obj(os.path.join(out, "ball.obj"), [tuple(0.1 * c for c in p) for p in v], f)
    rng = random.Random(65)
    write_obj(os.path.join(out, "rock.obj"), [tuple(0.1 * (1 + rng.uniform(-0.15, 0.15)) * c for c in p) for p in v], f)
    write_obj(os.path.join(out, "cup.obj"), *lathe(CUP_SECTION, 48))
    # The bowl's section, counter-clockwise in (r, y): from the bottom's middle round the
    # hemisphere to its rim, up the wall, in along the lid.
    rim = 0.24
    bowl = [(0.22 * math.sin(a), rim - 0.22 * math.cos(a)) for a in (math.pi / 2 * k / 12 for k in range(13))]
    bowl += [(0.22, 0.5), (0.0, 0.5)]
    write_obj(os.path.join(out, "bowl.obj"), *lathe(bowl, 48))
    blade = [(-0.15, 0.0), (0.15, 0.0), (0.15, 0.2), (0.015, 0.2), (0.015, 0.45), (-0.015, 0.45),
             (-0.015, 0.2), (-0.15, 0.2)]
    write_obj(os.path.join(out, "paddle.obj"), *extrude(blade, (0.0, 0.15), 0.04))
    write_obj(os.path.join(out, "hull.obj"),
              [(0.3 * x, 0.1 * y if y < 0 else 0.02 * y, 0.12 * z) for x, y, z in v], f)


if __name__ == "__main__":
    main()
