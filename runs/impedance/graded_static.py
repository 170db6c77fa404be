#!/usr/bin/env python3
"""Static stiffness of the rigid square footing on grids graded toward its edges (issue 46: the
rocking stiffness within 5 % at h = B/4?). static_stiffness.py's runs (2B x 2B footing, B = 1 m, on
a 6 m x 6 m surface, each mode held from the first step with the symmetry planes it allows, beta =
c_s dt / h = 0.5, K from the settled last step) with -ssi_mesh_grade g: the grid lines cluster
toward the footing's edges at the same number of elements (petsc_ssi/mesh/surface.py).

    .venv/bin/python runs/impedance/graded_static.py        (16 runs, a few minutes on 2 cores)

writes runs/impedance/graded_static.csv (K [N/m or N m/rad] and K / Pais-Kausel [-]) and the table
between <!-- graded:begin/end --> in runs/impedance/README.md, with, per mode, the limit h -> 0 of
the uniform grids (Richardson at order 1/2, the d^(-1/2) edge tractions', as static_stiffness.py),
the observed order of the graded (grade 1) grids' excess over that limit, and the element size at
which each kind of grid would come within 5 % of Pais and Kausel at its observed order; and the
same runs against an independent reference of the welded (bonded) square, the footing this code
models: petsc_ssi/analytic/disk_static.square_stiffness (Boussinesq-Cerruti, only the footing
meshed, n x n cells graded toward its edges) at n = 18, 27, 36 with Richardson's limit at the
observed order, each BEM case's excess over it and the observed order of that excess.
"""
import math
import csv
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from static_stiffness import MODES, OUT  # noqa: E402
from petsc_ssi.launch import child_env  # noqa: E402

CASES = [(0.5, 0.0), (0.5, 1.0), (0.25, 0.0), (0.25, 0.5), (0.25, 1.0)]     # (h [m], grade)
L = 6.0


def run(mode, h, grade):
    opt, val, sym, what, comp, ref, amp = MODES[mode]
    dt = 0.5 * h / 316.0
    out = os.path.join(OUT, f"graded-{mode}-h{h:g}-g{grade:g}.h5")
    if not os.path.exists(out):
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "2", sys.executable, "-m", "petsc_ssi",
               "-ssi_problem", "bem", "-ssi_mesh_size", f"{L:g},{L:g}", "-ssi_mesh_h", f"{h:g}", "-ssi_mesh_patch",
               "1,1", "-ssi_mesh_grade", f"{grade:g}", "-ssi_disp_group", "load", opt, val, "-ssi_symmetry", sym,
               "-ssi_dt", repr(dt), "-ssi_t_end", repr(max(0.1, 3.0 * L / 316.0)), "-ssi_output_stride", "0",
               "-ssi_warn_beta", "0", "-ssi_output", out, "-ssi_output_overwrite"]
        subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True, env=child_env(OPENBLAS_NUM_THREADS="1"))
    import h5py
    with h5py.File(out) as f:
        x = f["resultants"][what][:, comp] / amp
    wall = json.load(open(out[:-3] + ".json"))["stats"]["wall_s"]
    return float(x[-1]), float(np.ptp(x[-30:]) / abs(x[-1])), wall


def limit(ns, ks):
    """Richardson's limit of k(n) = L + C n^-p through three levels (p solved from their ratios)."""
    from scipy.optimize import brentq
    (n1, n2, n3), (k1, k2, k3) = ns, ks
    ratio = (k2 - k1) / (k3 - k2)
    f = lambda p: (n1 ** -p - n2 ** -p) / (n2 ** -p - n3 ** -p) - ratio
    p = brentq(f, 0.05, 8.0)
    return k3 + (k3 - k2) * n3 ** -p / (n2 ** -p - n3 ** -p), p


def welded_square(ns=(18, 27, 36)):
    """{mode: ((K at each n), Richardson's limit, its order)} [N/m or N m/rad] of the welded rigid
    square (B = 1 m) on this soil, from petsc_ssi.analytic.disk_static.square_stiffness."""
    sys.path.insert(0, ROOT)
    from petsc_ssi.analytic.disk_static import square_stiffness
    G = 2000.0 * 316.0 ** 2
    nu = ((548 / 316) ** 2 - 2) / (2 * ((548 / 316) ** 2 - 1))
    Ks = [square_stiffness(n, G, nu) for n in ns]
    out = {}
    for mode, i in {"vertical": 1, "horizontal": 0, "rocking": 2, "torsion": 3}.items():
        ks = tuple(K[i, i] for K in Ks)
        out[mode] = (ks,) + limit(ns, ks)
    return out


def coupling(h, grade):
    """(K_x, K_hr, K_rh) [N/m, N, N] of one grid from its horizontal and rocking runs: K_hr the
    moment M_y per u_x, K_rh the force F_x per theta_y (petsc-ssi impedance's convention)."""
    import h5py
    amp = MODES["horizontal"][6]
    with h5py.File(os.path.join(OUT, f"graded-horizontal-h{h:g}-g{grade:g}.h5")) as f:
        kx, khr = f["resultants/force"][-1, 0] / amp, f["resultants/moment"][-1, 1] / amp
    with h5py.File(os.path.join(OUT, f"graded-rocking-h{h:g}-g{grade:g}.h5")) as f:
        krh = f["resultants/force"][-1, 0] / MODES["rocking"][6]
    return float(kx), float(khr), float(krh)


def main():
    os.makedirs(OUT, exist_ok=True)
    rows = []
    for mode, spec in MODES.items():
        for h, g in CASES:
            K, settled, wall = run(mode, h, g)
            rows.append({"mode": mode, "h [m]": h, "grade [-]": g, "K [N/m or N m/rad]": K,
                         "K / Pais-Kausel [-]": K / spec[5], "settled (last 30 steps, relative) [-]": settled,
                         "wall [s]": wall})
            print(f"{mode:10s} h {h:g} grade {g:g}: K/K_ref = {K / spec[5]:.4f} (settled {settled:.1e}, {wall:.1f} s)",
                  flush=True)
    with open(os.path.join(HERE, "graded_static.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    head = " | ".join(f"h {h:g} m, grade {g:g}" for h, g in CASES)
    table = [f"| mode | {head} |", "|---" * (len(CASES) + 1) + "|"]
    for mode in MODES:
        r = {(x["h [m]"], x["grade [-]"]): x["K / Pais-Kausel [-]"] for x in rows if x["mode"] == mode}
        table.append(f"| {mode} | " + " | ".join(f"{r[c]:.3f}" for c in CASES) + " |")
    table.append("")
    for mode, spec in MODES.items():
        r = {(x["h [m]"], x["grade [-]"]): x["K [N/m or N m/rad]"] for x in rows if x["mode"] == mode}
        lim = r[(0.25, 0.0)] + (r[(0.25, 0.0)] - r[(0.5, 0.0)]) / (math.sqrt(2.0) - 1.0)
        line = f"- {mode}: uniform grids' limit h -> 0 = {lim / spec[5]:.3f} of Pais-Kausel"
        for g in (0.0, 1.0):
            e1, e2 = r[(0.5, g)] - lim, r[(0.25, g)] - lim
            if not (e1 > e2 > 0):
                line += f"; grade {g:g}: no monotone excess to extrapolate"
                continue
            p = math.log(e1 / e2) / math.log(2.0)
            line += f"; grade {g:g}: excess falls at order {p:.2f}"
            need = 1.05 * spec[5] - lim
            if r[(0.25, g)] <= 1.05 * spec[5]:
                line += ", within 5 % already at h = 0.25 m"
            elif need > 0:
                h5 = 0.25 * (need / e2) ** (1.0 / p)
                line += f", within 5 % at h = {h5:.3g} m ({(0.25 / h5) ** 2:.3g} x the elements of h = 0.25 m)"
        table.append(line)
    table += ["", "Against the independent welded square (its limit n -> infinity, in units of Pais and Kausel; "
              "the BEM's excess over it in %, h = 0.5 / 0.25 m, and the excess's observed order):", "",
              "| mode | welded square / Pais-Kausel (n = 18, 27, 36; limit) | uniform grid: excess %, order | "
              "graded (1): excess %, order | graded (0.5) at h = 0.25 m: excess % |", "|---|---|---|---|---|"]
    welded = welded_square()
    for mode, spec in MODES.items():
        r = {(x["h [m]"], x["grade [-]"]): x["K [N/m or N m/rad]"] for x in rows if x["mode"] == mode}
        levels, lim, p_lim = welded[mode]
        cells = [f"{v / spec[5]:.4f}" for v in levels] + [f"{lim / spec[5]:.4f} (order {p_lim:.2f})"]
        out = []
        for g in (0.0, 1.0):
            e1, e2 = r[(0.5, g)] / lim - 1, r[(0.25, g)] / lim - 1
            order = f"{math.log(e1 / e2) / math.log(2.0):.2f}" if e1 > e2 > 0 else "-"
            out.append(f"{100 * e1:.1f} / {100 * e2:.1f}, {order}")
        table.append(f"| {mode} | {', '.join(cells[:3])}; {cells[3]} | {out[0]} | {out[1]} | "
                     f"{100 * (r[(0.25, 0.5)] / lim - 1):.1f} |")
    sys.path.insert(0, ROOT)
    from petsc_ssi.analytic.disk_static import square_stiffness
    nu = ((548 / 316) ** 2 - 2) / (2 * ((548 / 316) ** 2 - 1))
    Kw = square_stiffness(36, 1.0, nu)
    ref = 0.5 * (Kw[2, 0] + Kw[0, 2]) / Kw[0, 0]
    table += ["", f"The horizontal-rocking coupling (B = 1 m; the welded square at n = 36: K_hr / (B K_x) = "
              f"{Kw[2, 0] / Kw[0, 0]:.4f}, K_rh / (B K_x) = {Kw[0, 2] / Kw[0, 0]:.4f}):", "",
              "| grid | K_hr / (B K_x) | K_rh / (B K_x) | K_hr / K_rh - 1 | K_hr, K_rh, their mean vs the welded square (%) |",
              "|---|---|---|---|---|"]
    for h, g in CASES:
        kx, khr, krh = coupling(h, g)
        a, b = khr / kx, krh / kx
        table.append(f"| h {h:g} m, grade {g:g} | {a:.4f} | {b:.4f} | {khr / krh - 1:.3f} | "
                     f"{100 * (a / ref - 1):+.1f}, {100 * (b / ref - 1):+.1f}, {100 * (0.5 * (a + b) / ref - 1):+.1f} |")
    readme = os.path.join(HERE, "README.md")
    text = open(readme).read()
    b, e = "<!-- graded:begin -->", "<!-- graded:end -->"
    if b in text:
        i, j = text.index(b) + len(b), text.index(e)
        open(readme, "w").write(text[:i] + "\n" + "\n".join(table) + "\n" + text[j:])
    print("\n".join(table))


if __name__ == "__main__":
    main()
