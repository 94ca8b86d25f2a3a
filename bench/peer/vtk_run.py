#!/usr/bin/env python3
"""SPlisHSPlasH's exported frames as a pbflow run directory, so that pbflow's own yardsticks
(bench/boundary.py) read the peer's fluid as they read pbflow's: each legacy VTK particle file
(binary, big-endian; "density" and "velocity" among its attributes) becomes
particles/frame_NNNNN.ply (x, y, z, density, vx, vy, vz), numbered in the peer's order, and
run.json carries the pbflow scene the peer's was written from. A particle outside the scene's
domain (one the peer's walls let through) is left out, and counted.
  vtk_run.py PBFLOW_SCENE_JSON OUT_DIR VTK_FILE...    (VTK files in any order)"""
import json
import os
import re
import struct
import sys


def field(data, header, components):
    """The values after a header line of the form `NAME COMPONENTS N TYPE`, or `POINTS N TYPE`."""
    m = re.search(rb"\n" + header + rb" (\d+) (float|double)\n", data)
    if not m:
        raise SystemExit(f"no {header.decode()} field in a SPlisHSPlasH VTK file")
    n, kind = int(m.group(1)), "f" if m.group(2) == b"float" else "d"
    values = struct.unpack_from(f">{components * n}{kind}", data, m.end())
    return [values[k * components:(k + 1) * components] for k in range(n)]


def frame_number(path):
    """The last number in a peer file's name: its frame, for sorting."""
    found = re.findall(r"(\d+)", path)
    return int(found[-1]) if found else 0


def write_ply(path, rows):
    """rows: (x, y, z, density, vx, vy, vz) a particle."""
    names = ("x", "y", "z", "density", "vx", "vy", "vz")
    header = "ply\nformat binary_little_endian 1.0\nelement vertex %d\n%send_header\n" % (
        len(rows), "".join(f"property float {n}\n" for n in names))
    with open(path, "wb") as f:
        f.write(header.encode())
        for row in rows:
            f.write(struct.pack("<7f", *row))


def in_domain(domain, p):
    return all(domain["min"][a] <= p[a] <= domain["max"][a] for a in range(3))


def main(args):
    if len(args) < 3:
        raise SystemExit(__doc__)
    scene, out, files = json.load(open(args[0])), args[1], sorted(args[2:], key=frame_number)
    os.makedirs(os.path.join(out, "particles"), exist_ok=True)
    json.dump({"scene": scene}, open(os.path.join(out, "run.json"), "w"), indent=1)
    escaped = 0
    for k, path in enumerate(files):
        data = open(path, "rb").read()
        rows = [(*p, d[0], *v) for p, d, v in
                zip(field(data, rb"POINTS", 3), field(data, rb"density 1", 1), field(data, rb"velocity 3", 3))]
        kept = [row for row in rows if in_domain(scene["domain"], row)]
        escaped = max(escaped, len(rows) - len(kept))
        write_ply(os.path.join(out, "particles", f"frame_{k:05d}.ply"), kept)
    print(f"{len(files)} frames in {out}; at most {escaped} particles outside the domain (left out)")


if __name__ == "__main__":
    main(sys.argv[1:])
