#!/usr/bin/env python3
"""The peer's mean compression, from its own densities: the mean over its exported frames of
the mean over particles of max(rho / rho0 - 1, 0), as pbflow's summary reports its own.
Reads SPlisHSPlasH's legacy VTK particle files (binary, big-endian; "density" among the
exported attributes).
  compression.py RHO0 FILE...   -> the mean compression, a fraction"""
import re
import struct
import sys


def densities(path):
    with open(path, "rb") as f:
        data = f.read()
    m = re.search(rb"\ndensity 1 (\d+) (float|double)\n", data)
    if not m:
        raise SystemExit(f"compression.py: {path} holds no density field")
    n, size = int(m.group(1)), 4 if m.group(2) == b"float" else 8
    return struct.unpack_from(f">{n}{'f' if size == 4 else 'd'}", data, m.end())


def frame_number(path):
    found = re.findall(r"(\d+)", path)
    return int(found[-1]) if found else 0


def main(args):
    if len(args) < 2:
        raise SystemExit(__doc__)
    rho0, files = float(args[0]), sorted(args[1:], key=frame_number)
    means = []
    for path in files:
        rho = densities(path)
        means.append(sum(max(r / rho0 - 1.0, 0.0) for r in rho) / max(len(rho), 1))
    print(f"{sum(means) / len(means):.6g}")


if __name__ == "__main__":
    main(sys.argv[1:])
