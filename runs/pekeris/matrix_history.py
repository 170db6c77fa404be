#!/usr/bin/env python3
"""Time histories of single lag-matrix entries, exact against interpolated
(the paper's Figs. 5-6): H_31 and G_33 between the collocation node at r = 0
and the nodes at r = 5 m and 15 m on the x axis, for tau_L = 0.5, 1, 1.5 with
the paper's k, multi-linear (ML) and Chebyshev-Lagrange (CL).

The paper's full 36 m x 36 m mesh (no symmetry: in a quarter model a column
folds in its mirror images), dt = 7.5e-4 s; only the row of the node at the
origin is assembled (a few seconds). H_31: row component z (load direction 3)
and column component x (1); G_33: z and z, with every node a traction column.
Writes matrix_history_r5.png, matrix_history_r15.png and matrix_history.csv here.
"""
import csv
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(os.path.dirname(HERE)))

from petsc_ssi.petsc import init  # noqa: E402

KS = {5: {0.5: 18, 1.0: 17, 1.5: 15}, 15: {0.5: 15, 1.0: 10, 1.5: 6}}


def entries(ls, node, tcol, lag):
    out = []
    for B, col, comp in ((ls.H, node, (2, 0)), (ls.G, tcol, (2, 2))):
        r, c, v = B.peek(lag)
        m = c == col
        out.append(float(v[m][0][comp]) if m.any() else 0.0)
    return out


def main():
    PETSc = init(["matrix_history"])
    from petsc_ssi.mesh.surface import grid
    from petsc_ssi.bem.lagset import Material, Regions, LagSet
    from petsc_ssi.bem import interp
    comm = PETSc.COMM_SELF
    mat = Material(548.0, 316.0, 2000.0)
    dt = 7.5e-4
    mesh = grid(36.0, 36.0, 1.0)
    reg = Regions(mesh, load_elems=np.arange(mesh.n_cells))
    opts = {"gauss": 2, "singular_order": 12, "subdivisions": 4, "near_factor": 2.0,
            "max_subdivisions": 32, "cache": True}
    i0 = int(np.argmin(np.linalg.norm(mesh.nodes, axis=1)))
    L = int(np.floor(36 * np.sqrt(2) / (mat.cs * dt))) + 2
    ls = LagSet(comm, mesh, mat, dt, L, reg, [], opts)
    ls.rows = np.array([i0])
    ls.assemble()
    H, G = ls.H, ls.G
    tau = (np.arange(1, L + 1) - 1) * dt
    rows = []
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    for r in (5, 15):
        j = int(np.argmin(np.linalg.norm(mesh.nodes - [r, 0, 0], axis=1)))
        tc = int(np.searchsorted(reg.tnode, j))
        ls.H, ls.G = H, G
        exact = np.array([entries(ls, j, tc, l) for l in range(1, L + 1)])
        fig, axs = plt.subplots(3, 2, figsize=(11, 9), sharex=True)
        for row, (tl, k) in enumerate(KS[r].items()):
            TL = tl * r / mat.cs
            for meth, mk, lab in (("linear", "k.", "ML"), ("chebyshev", "o", "CL")):
                plan = interp.Plan(meth, dt, L, TL, k)
                vals = []
                for jj in range(plan.k):
                    lag, toff = plan.kernel_time(jj)
                    ls.assemble(lag_lo=lag, lag_hi=lag, toff=toff)
                    vals.append(entries(ls, j, tc, lag))
                vals = np.array(vals)
                approx = np.vstack([exact[:plan.Lx], plan.W @ vals])
                for c in range(2):
                    ax = axs[row, c]
                    sel = slice(plan.Lx, L)
                    ax.plot(tau[sel] * 1e3, approx[sel, c], mk, ms=3.5 if meth == "linear" else 4,
                            mfc="none" if meth == "chebyshev" else None, label=f"{lab}, k = {k}")
                    err = np.linalg.norm(approx[:, c] - exact[:, c]) / np.linalg.norm(exact[:, c])
                    rows.append({"r_m": r, "tau_L": tl, "k": k, "method": lab, "entry": ["H31", "G33"][c],
                                 "rel_l2_error": err})
            for c in range(2):
                ax = axs[row, c]
                ax.plot(tau * 1e3, exact[:, c], color="0.6", lw=1.2, label="exact (non-interpolated)", zorder=0)
                ax.axvline(TL * 1e3, color="0.8", ls=":")
                ax.set_title(f"{['$H_{31}$', '$G_{33}$'][c]}, r = {r} m, $\\tau_L$ = {tl}")
                ax.grid(alpha=0.3)
                if row == 2:
                    ax.set_xlabel("lag time (l - 1) dt (ms)")
            axs[row, 0].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(HERE, f"matrix_history_r{r}.png"), dpi=110)
        plt.close(fig)
    with open(os.path.join(HERE, "matrix_history.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    for x in rows:
        print(x)


if __name__ == "__main__":
    main()
