#!/usr/bin/env python3
"""The peer's mean compression, from its own densities: the mean over its exported frames of
the mean over particles of max(rho / rho0 - 1, 0), as pbflow's summary reports its own.
Reads SPlisHSPlasH's legacy VTK particle files (binary, big-endian; "density" among the
exported attributes).
  compression.py RHO0 FILE...   -> the mean compression, a fraction"""
import sys

from vtk_run import field, frame_number


def main(args):
    if len(args) < 2:
        raise SystemExit(__doc__)
    rho0, files = float(args[0]), sorted(args[1:], key=frame_number)
    means = []
    for path in files:
        rho = [d for d, in field(open(path, "rb").read(), rb"density 1", 1)]
        means.append(sum(max(r / rho0 - 1.0, 0.0) for r in rho) / max(len(rho), 1))
    print(f"{sum(means) / len(means):.6g}")


if __name__ == "__main__":
    main(sys.argv[1:])
