#!/usr/bin/env python3
"""Mesh convergence of the shell obstacle course -> convergence.csv and convergence.png.

Runs ``petsc_ssi.fem.obstacle.convergence_table`` (the MITC4 + drilling shell of
fem/elements/shell.py, assembled and solved by obstacle.py's own small scipy solver, not
through PETSc) for each problem of ``obstacle.PROBLEMS`` over a mesh sweep:

  scordelis_lo      Scordelis-Lo roof, quarter, n x n, uz at the free-edge midspan (-0.3024)
  pinched_cylinder  pinched cylinder with diaphragms, octant, n x n, uz under the load (-1.8249e-5)
  twisted_beam_in   twisted beam, 6n x n, in-plane tip load (5.424e-3)
  twisted_beam_out  twisted beam, 6n x n, out-of-plane tip load (1.754e-3)
  fv16              NAFEMS FV16 cantilevered plate, n x n, 6 lowest frequencies
  ss_plate          simply supported plate 1.5 x 1 x 0.002, 1.5n x n, 6 lowest frequencies (Navier)

Writes one CSV row per (problem, mesh, quantity): quantity 0 for the static problems, modes 1..6
for the modal ones, with value, reference, relative error = (value - reference) / |reference|,
free dofs and the wall time of the solve. The PNG: |relative error| against free dofs, log-log,
one line per problem (modal problems: the largest |error| of the six modes).

    .venv/bin/python runs/structures/convergence.py            # then runs/structures/report.py
"""
import argparse
import csv
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", ".."))

from petsc_ssi.fem import obstacle  # noqa: E402

MESHES = {
    "scordelis_lo": [2, 4, 8, 16, 32, 64],
    "pinched_cylinder": [2, 4, 8, 16, 32, 64],
    "twisted_beam_in": [1, 2, 4, 8, 16],
    "twisted_beam_out": [1, 2, 4, 8, 16],
    "fv16": [2, 4, 8, 16, 32, 64],
    "ss_plate": [4, 8, 16, 32, 64],
}
FIELDS = ["problem", "n", "mesh", "free_dofs", "quantity", "value", "reference", "rel_error", "solve_s"]


def run(meshes):
    rows = []
    for name, ns in meshes.items():
        make = obstacle.PROBLEMS[name]
        for n in ns:
            t0 = time.perf_counter()
            ((_, note, dofs, v, err),) = obstacle.convergence_table(make, [n])
            dt = time.perf_counter() - t0
            ref = np.atleast_1d(make(n).reference)
            for q, (vq, eq, rq) in enumerate(zip(np.atleast_1d(v), np.atleast_1d(err), ref)):
                rows.append(dict(problem=name, n=n, mesh=note, free_dofs=dofs,
                                 quantity=q + 1 if ref.size > 1 else 0, value=f"{vq:.8g}",
                                 reference=f"{rq:.8g}", rel_error=f"{eq:.6g}", solve_s=f"{dt:.3g}"))
            worst = np.max(np.abs(np.atleast_1d(err)))
            print(f"[convergence] {name:17s} n={n:3d} {note:>10s} dofs={dofs:7d} max|err|={100 * worst:.3g}% "
                  f"({dt:.2f} s)", flush=True)
    return rows


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 5))
    for name in dict.fromkeys(r["problem"] for r in rows):
        sel = [r for r in rows if r["problem"] == name]
        ns = sorted({int(r["n"]) for r in sel})
        x, y = [], []
        for n in ns:
            rr = [r for r in sel if int(r["n"]) == n]
            x.append(int(rr[0]["free_dofs"]))
            y.append(max(abs(float(r["rel_error"])) for r in rr))
        modal = len(rr) > 1
        ax.loglog(x, y, "o-", label=name + (" (max of 6 modes)" if modal else ""))
    ax.set_xlabel("free dofs")
    ax.set_ylabel("|relative error|")
    ax.set_title("Shell obstacle course: MITC4 + drilling (fem/obstacle.py)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--csv", default=os.path.join(HERE, "convergence.csv"))
    ap.add_argument("--png", default=os.path.join(HERE, "convergence.png"))
    ap.add_argument("--quick", action="store_true", help="the three coarsest meshes of each problem")
    a = ap.parse_args(argv)
    meshes = {k: v[:3] for k, v in MESHES.items()} if a.quick else MESHES
    rows = run(meshes)
    with open(a.csv, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)
    plot(rows, a.png)
    print(f"[convergence] wrote {a.csv}, {a.png}")


if __name__ == "__main__":
    main()
