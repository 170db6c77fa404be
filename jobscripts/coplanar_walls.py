#!/usr/bin/env python3
"""Why the pit's wall blocks are not split into the flat pattern (runs/basement/README.md, "The coplanar
pairs' flat pattern"): on the test pit of tests/bem/test_coplanar_pattern.py (6 m ground, 2 x 2 x 1 m pit,
0.5 m nodes, lags 1-6, the general 9-entry storage), per lag the largest entry outside the rotated flat
pattern of the wall x = +1 m (H couples x with y and z only) over the block's largest, for two sets of blocks
of a row node on that wall: column nodes anywhere on the wall (its edges' nodes belong to elements of the
neighbouring planes too) and column nodes inside the wall (every element around them in the wall's plane).

    PETSC_DIR=... .venv/bin/python jobscripts/coplanar_walls.py
"""
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "tests"), os.path.join(ROOT, "tests", "bem"), ROOT]
from test_coplanar_pattern import _lagset, _blocks  # noqa: E402

OFF = [(0, 0), (1, 1), (1, 2), (2, 1), (2, 2)]      # zero for a pair in the plane x = const


def main():
    ls = _lagset("full")
    H, _ = ls.assemble()
    X = ls.mesh.nodes
    tol = 1e-9
    wall = {i for i, (x, y, z) in enumerate(X) if abs(x - 1) < tol and z <= tol and abs(y) <= 1 + tol}
    inner = {i for i in wall if abs(X[i, 1]) < 1 - tol and -1 + tol < X[i, 2] < -tol}
    print("| lag | column nodes anywhere on the wall: blocks, largest off-pattern / block largest [-] | "
          "column nodes inside the wall: blocks, largest [-] |")
    print("|---|---|---|")
    for lag in range(1, ls.L + 1):
        out = []
        for cols in (wall, inner):
            ratios = [max(abs(b[p]) for p in OFF) / np.abs(b).max() for (r, c), b in _blocks(H, lag).items()
                      if r in wall and c in cols and r != c and np.abs(b).max() > 0]
            out.append(f"{len(ratios)}, {max(ratios):.2g}" if ratios else "0, -")
        print(f"| {lag} | {out[0]} | {out[1]} |")


if __name__ == "__main__":
    main()
