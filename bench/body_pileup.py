#!/usr/bin/env python3
"""Bodies piling up in shallow water, the energy bars' worst case for contacts: a heavy box
dropped on the floor, a light one beside it, and a ball thrown at a wall-high obstacle to land on
either, at twelve throws. Each run's largest energy gain (the energy bars: kinetic and potential
energy of the water and the bodies less the solids' work, over the water's potential energy at
frame 0) and its frame.
    bench/body_pileup.py DEVICE        (cpu, or a GPU as --device takes it; needs build/pbflow)"""
import csv
import itertools
import json
import os
import subprocess
import sys
import tempfile

SCENE = {"domain": {"min": [0, 0, 0], "max": [0.4, 0.5, 0.2]}, "particle_spacing": 0.02,
         "fluid_blocks": [{"min": [0, 0, 0], "max": [0.4, 0.06, 0.2]}],
         "obstacles": [{"type": "box", "min": [0, 0, 0], "max": [0.08, 0.2, 0.2]}],
         "bodies": [{"type": "box", "min": [0.12, 0.2, 0.05], "max": [0.22, 0.26, 0.15], "density": 1500},
                    {"type": "sphere", "centre": [0.3, 0.3, 0.1], "radius": 0.04, "density": 2000},
                    {"type": "box", "min": [0.3, 0.4, 0.05], "max": [0.36, 0.44, 0.15], "density": 700}]}


def largest_gain(stats):
    work, e0, pe0, best = 0.0, None, None, (0.0, 0)
    for row in csv.DictReader(open(stats)):
        work += float(row["solid_work"]) + float(row["flow_energy"])
        e = float(row["kinetic_energy"]) + float(row["potential_energy"]) + float(row["body_energy"]) - work
        if e0 is None:
            e0, pe0 = e, float(row["potential_energy"])
        best = max(best, ((e - e0) / pe0, int(row["frame"])))
    return best


def main():
    device = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        print("| ball at x | thrown (m/s) | largest gain | at frame |\n|---|---|---|---|")
        for (vx, vy), x in itertools.product([(-2.5, 0), (-2.5, 1), (-1.5, 0), (-1.5, 1), (-0.8, 0), (-0.8, 1)], [0.3, 0.25]):
            scene = json.loads(json.dumps(SCENE))
            scene["bodies"][1].update(centre=[x, 0.3, 0.1], velocity=[vx, vy, 0])
            path = os.path.join(tmp, "scene.json")
            json.dump(scene, open(path, "w"))
            out = os.path.join(tmp, "run")
            subprocess.run(["build/pbflow", "run", path, "--device", device, "--no-render", "--quiet", "--frames", "120",
                            "--out", out], check=True)
            gain, frame = largest_gain(os.path.join(out, "stats.csv"))
            print(f"| {x} | ({vx}, {vy}) | {100 * gain:.2f} % | {frame} |", flush=True)


if __name__ == "__main__":
    main()
