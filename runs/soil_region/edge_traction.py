#!/usr/bin/env python3
"""The interface's nodal traction near a filled pit's edges (README "Limitations", runs/soil_region/README.md):
the pit of tests/coupling/test_excavation_coupled.py (2 x 2 x 1 m filled with the same soil, vertical S, a
40 ms sin^4 pulse; the quarter model) at soil elements h = 1 and 0.5 m. The region scatters nothing, so
the soil's scattered traction on the interface (interface/p - interface/pff in the output: the total
minus the free field's t_ff) would vanish; what it is, per kind of node, as a share of the free field's
largest nodal traction (over nodes and steps), and its resultant against the free field's resultant:

    node kind     the interface nodes at the ground (z = 0), on the walls, and on the bottom: at its
                  nine-node elements' corners, and at their mid-side and centre nodes
    scattered     max |p - pff| over those nodes and the steps / max |pff| over all nodes and steps
    resultant     max_t |F_x - F_ff| / max_t |F_ff|: the soil's force on the region against the free
                  field's (the region's inertia; ``resultant_error``)

Prints the table and writes edge_traction.csv here.
    .venv/bin/python runs/soil_region/edge_traction.py        (about a minute on one core)
"""
import csv
import os
import subprocess
import sys
import tempfile

import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tests"))
sys.path.insert(0, os.path.join(ROOT, "tests", "coupling"))


def run(h, tmp):
    from pathlib import Path
    import test_excavation_coupled as T
    a = T.quarter(Path(tmp), f"q{h}.h5", h=h)
    env = child_env(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    subprocess.run([sys.executable, "-m", "petsc_ssi"] + a[1:], cwd=ROOT, env=env, check=True,
                   stdout=subprocess.DEVNULL)
    return os.path.join(tmp, f"q{h}.h5")


def kinds(x, h, tol=1e-9):
    """The node kind of each interface node of the pit [-1, 1]^2 x [-1, 0] (quarter x, y >= 0): at the
    ground, on a wall, on the bottom at a nine-node element's corner (x, y multiples of h) or at its
    mid-side and centre nodes."""
    z = x[:, 2]
    corner = np.all(np.abs(x[:, :2] / h - np.rint(x[:, :2] / h)) < tol, axis=1)
    return np.where(np.abs(z) < tol, "ground", np.where(np.abs(z + 1) < tol,
                    np.where(corner, "bottom, element corners", "bottom, mid-side and centre"), "wall"))


def resultant_error(path):
    """max_t |F_x - F_ff| / max_t |F_ff|: the soil's force on the region (interface/force_fe, the quarter's)
    against the free field's, which is the region's inertia (tests/coupling/test_excavation_coupled.py's
    region_errors: rho A (c_s / 2) [v(t + d/c_s) - v(t - d/c_s)] as the step's mean, A = 1 m^2 here)."""
    import h5py
    import test_excavation_coupled as T
    with h5py.File(path) as f:
        ti, F = f["interface/t"][:], f["interface/force_fe"][:, 0]
        D, td, t0 = f["seismic/x_displacement"][:], f["seismic/x_t"][:], float(f["seismic/t0"][()])
    dt, d = ti[1] - ti[0], 1.0

    def vmean(s):
        return (np.interp(ti - t0 + s, td, D, left=0.0) - np.interp(ti - dt - t0 + s, td, D, left=0.0)) / dt
    F_ref = T.RHO * 1.0 * T.CS / 2.0 * (vmean(d / T.CS) - vmean(-d / T.CS))
    return float(np.abs(F - F_ref).max() / np.abs(F_ref).max())


def weakest_traction_mode(ne=4):
    """The matrix that hands a nine-node traction to bilinear brick faces of half the element's size,
    T_ij = int phi_i psi_j dA, on ne x ne elements (tensor product of the 1-D one: quadratic psi on
    elements of size 1, linear hats phi on the same nodes): (its condition number, the 1-D factor's
    weakest singular vector at the nodes, scaled to 1). A traction along that mode does the least work
    on the bricks' displacements, so the coupled system determines it worst."""
    from numpy.polynomial.legendre import leggauss
    n = 2 * ne + 1
    xg, wg = leggauss(6)
    T = np.zeros((n, n))
    for e in range(ne):
        for sub in range(2):
            a = e + 0.5 * sub
            x, w = (xg + 1) / 4 + a, wg / 4
            s = x - e
            psi = (2 * (s - 0.5) * (s - 1), -4 * s * (s - 1), 2 * s * (s - 0.5))
            t = (x - a) / 0.5
            for i, ph in enumerate((1 - t, t)):
                for j, ps in enumerate(psi):
                    T[2 * e + sub + i, 2 * e + j] += np.sum(w * ph * ps)
    sv = np.linalg.svd(np.kron(T, T))[1]
    v = np.linalg.svd(T)[2][-1]
    return float(sv.max() / sv.min()), v / np.abs(v).max()


def main():
    import h5py
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for h in (1.0, 0.5):
            path = run(h, tmp)
            with h5py.File(path) as f:
                g = f["interface"]
                x, p, pff = g["x"][:], g["p"][:], g["pff"][:]
            sc = p - pff
            peak = np.abs(pff).max()
            k = kinds(x, h)
            for kind in ("ground", "wall", "bottom, element corners", "bottom, mid-side and centre"):
                sel = k == kind
                if sel.any():
                    rows.append({"h [m]": h, "node kind": kind, "nodes": int(sel.sum()),
                                 "max |p - pff| / max |pff|": round(float(np.abs(sc[:, sel]).max() / peak), 4)})
            rows.append({"h [m]": h, "node kind": "resultant (x)", "nodes": int(len(x)),
                         "max |p - pff| / max |pff|": round(resultant_error(path), 4)})
    with open(os.path.join(HERE, "edge_traction.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print("| h [m] | node kind | nodes | scattered / free field's peak |\n|---|---|---|---|")
    for r in rows:
        print(f"| {r['h [m]']:g} | {r['node kind']} | {r['nodes']} | {r['max |p - pff| / max |pff|']} |")
    cond, v = weakest_traction_mode()
    print(f"nine-node traction to bilinear brick faces (4 x 4 elements): condition number {cond:.3g}; the 1-D "
          f"factor's weakest mode at the nodes (corner, mid, corner, ...): {np.round(v, 2).tolist()}")


if __name__ == "__main__":
    main()
