#!/usr/bin/env python3
"""The coupled step's x -= Z d on a mirror-symmetric region (coupling/columns.py ``MirroredZ``) against the product
with every column, at the uniform 72 m building's sizes on one of its 2 ranks (6863 region rows, 1425 columns, 390
of them the orbits' representatives: jobscripts/building_uniform.sh's uniform-72-area-exact log), one process:
ms per product of every column (numpy's matrix-vector product, what a step did before), of the representatives'
for the four right-hand sides of the mirror group by ``columns._rows4`` (one pass over their rows), by BLAS's
product with a matrix of four columns, and by four matrix-vector products. Random values; the results compared.
Best of 5 runs of 50 products each.

    python jobscripts/mirrored_z_rate.py [ROWS COLUMNS REPRESENTATIVES]
"""
import sys
import time

import numpy as np

sys.path.insert(0, ".")
from petsc_ssi.coupling.columns import _rows4  # noqa: E402

rows, cols, reps = (int(a) for a in sys.argv[1:4]) if len(sys.argv) > 3 else (6863, 1425, 390)
rng = np.random.default_rng(0)
Z = rng.standard_normal((rows, cols))
d = rng.standard_normal(cols)
Zr = np.ascontiguousarray(Z[:, :reps])
D = rng.standard_normal((4, reps))
Dt = np.ascontiguousarray(D.T)
Y = np.empty((rows, 4))
_rows4(Zr, D, Y)
assert np.abs(Y - Zr @ D.T).max() <= 1e-12 * np.abs(Y).max()


def best(f):
    f()
    t = []
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(50):
            f()
        t.append((time.perf_counter() - t0) / 50)
    return 1e3 * min(t)


print(f"{rows} rows, {cols} columns, {reps} representatives")
for name, f in (("every column, Z @ d", lambda: Z @ d),
                ("representatives, columns._rows4, 4 right-hand sides", lambda: _rows4(Zr, D, Y)),
                ("representatives, BLAS Z_r @ D^T (4 columns)", lambda: Zr @ Dt),
                ("representatives, 4 x Z_r @ d_g", lambda: [Zr @ D[g] for g in range(4)])):
    print(f"{name}: {best(f):.2f} ms")
