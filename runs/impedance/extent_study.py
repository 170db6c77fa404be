"""How far the meshed surface must reach around a footing: the square footing (B = 1 m) on
surfaces of 4, 6, 8 and 12 m (the distance d from the footing's edge to the mesh's edge 1, 2, 3 and
5 m), 0.5 m elements, dt = 0.792 ms (beta = 0.5), a 0.2 s record; `petsc-ssi impedance` for the
vertical, horizontal and rocking modes, each compared with the 12 m surface.

A truncated surface is exact until the waves the footing sends out have reached the mesh's edge
and come back; what the edge sends back spoils the long waves most. The band's lower limit that
`petsc-ssi impedance` uses (impedance.extent_limit) asks for one Rayleigh wavelength across the
meshed surface of extent L: a0 >= 2 pi B c_R / (c_s L). For each extent and mode the script
reports the largest deviation max(|dk|, |dc|) from the 12 m surface above that limit (up to
a0 = 2, past omega dt = 0.3 = a0 1.2, where dt's error is common to both meshes) and between the
record's limit (a0 = 0.2) and it.

    .venv/bin/python runs/impedance/extent_study.py        (about 4 minutes on 2 cores)

writes runs/impedance/extent_study.csv, extent_study.png and the table in README.md.
"""
import csv
import os
import subprocess
import sys

import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
OUT = os.path.join(ROOT, "out", "impedance")
EXTENTS = (4.0, 6.0, 8.0, 12.0)
MODES = ("vertical", "horizontal", "rocking")
A0_MAX = 2.0
A0_RECORD = 0.2          # two frequency bins of the 0.2 s record: 4 pi B / (c_s T)
B = 1.0
GAMMA = 1.0877           # c_s / c_R at nu = 0.251 (analytic/pekeris.py)


def run(L):
    stem = os.path.join(OUT, f"extent{L:g}")
    cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "2", sys.executable, "-m", "petsc_ssi",
           "impedance", "-ssi_problem", "bem", "-ssi_cp", "548", "-ssi_cs", "316", "-ssi_rho", "2000",
           "-ssi_mesh_size", f"{L:g},{L:g}", "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "1,1",
           "-ssi_disp_group", "load", "-ssi_dt", "7.92e-4", "-ssi_t_end", "0.2", "-ssi_output_stride", "0",
           "-ssi_warn_beta", "0", "-ssi_impedance_modes", ",".join(MODES),
           "-ssi_output", stem + ".h5", "-ssi_output_overwrite"]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True,
                       env=child_env(OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1"))
    if p.returncode:
        sys.exit(f"{' '.join(cmd)} failed:\n{p.stdout[-3000:]}{p.stderr[-3000:]}")
    out = {}
    for r in csv.DictReader(open(stem + "-impedance.csv")):
        out.setdefault(r["mode"], []).append((float(r["a0"]), float(r["k"]), float(r["c"])))
    return {m: np.array(v) for m, v in out.items()}


def main():
    os.makedirs(OUT, exist_ok=True)
    res = {}
    for L in EXTENTS:
        res[L] = run(L)
        print(f"extent {L:g} m done", flush=True)
    ref = res[EXTENTS[-1]]
    rows, curves = [], {}
    for L in EXTENTS[:-1]:
        lo = 2 * np.pi * B / (GAMMA * L)
        for m in MODES:
            a, k, c = res[L][m].T
            ar, kr, cr = ref[m].T
            sel = (a > 0) & (a <= A0_MAX)
            dev = np.maximum(np.abs(k - np.interp(a, ar, kr)), np.abs(c - np.interp(a, ar, cr)))[sel]
            a = a[sel]
            curves[(L, m)] = (a, dev, lo)
            rows.append(dict(extent_m=L, d_over_B=L / 2 / B - 1, mode=m, a0_limit=round(lo, 3),
                             max_dev_above=round(float(dev[a >= lo].max()), 4),
                             max_dev_below=round(float(dev[(a >= A0_RECORD) & (a < lo)].max()), 4)))
    with open(os.path.join(HERE, "extent_study.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    for r in rows:
        print(r)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, len(MODES), figsize=(13, 4), sharey=True)
    for ax, m in zip(axs, MODES):
        for L in EXTENTS[:-1]:
            a, dev, lo = curves[(L, m)]
            l, = ax.semilogy(a, np.maximum(dev, 1e-5), label=f"{L:g} m (d/B = {L / 2 - B:g})")
            ax.axvline(lo, color=l.get_color(), ls="--", lw=0.8)
        ax.set_title(m + " (dashed: each surface's lower limit)", fontsize=9)
        ax.set_xlabel("a0")
    axs[0].set_ylabel(f"max(|dk|, |dc|) against the {EXTENTS[-1]:g} m surface")
    axs[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "extent_study.png"), dpi=110)
    readme = os.path.join(HERE, "README.md")
    text = open(readme).read()
    lines = ["| surface | d / B | mode | lower limit a0 | max deviation above it | max deviation below it |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {r['extent_m']:g} m | {r['d_over_B']:g} | {r['mode']} | {r['a0_limit']:.2f} | "
              f"{r['max_dev_above']:.3f} | {r['max_dev_below']:.3f} |" for r in rows]
    b, e = "<!-- extent:begin -->", "<!-- extent:end -->"
    if b in text:
        text = text[:text.index(b) + len(b)] + "\n" + "\n".join(lines) + "\n" + text[text.index(e):]
        open(readme, "w").write(text)
    else:
        print("\n".join(lines))


if __name__ == "__main__":
    main()
