#!/usr/bin/env python3
"""Figures of the foundation example in the style of the paper's Figs. 8-11,
from the HDF5 outputs of jobscripts/foundation_bench.sh (1-rank runs):

  histories.png            vertical displacement at the interface points A_s, A_f
                           (soil / block at A) and B_s, B_f, each case (Figs. 9, 11)
  snapshots-<case>.png     section y = 0 of the soil surface and the block at
                           six instants, displacements exaggerated (Figs. 8, 10)

A and B: symmetric load A = base centre (0, 0), B = base edge (0.5, 0);
antisymmetric load A = (-0.5, 0) under the pushed half, B = (0.5, 0) under the
pulled half. Usage: python runs/foundation/figures.py OUT_DIR FIG_DIR
"""
import os
import sys

import h5py
import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

CASES = ["sym-bonded", "sym-unilateral", "anti-bonded", "anti-unilateral", "anti-unilateral-cohesive",
         "sym-bonded-staggered"]
POINTS = {"sym": {"A": (0.0, 0.0), "B": (0.5, 0.0)}, "anti": {"A": (-0.5, 0.0), "B": (0.5, 0.0)}}


def load(out, case):
    path = os.path.join(out, f"foundation-{case}-n1.h5")
    if not os.path.exists(path):
        return None
    d = {}
    with h5py.File(path, "r") as f:
        g = f["interface"]
        d.update({k: g[k][:] for k in g})
        d["soil_x"] = f["coordinates"][:].reshape(-1, 3)
        d["soil_t"] = f["time"][:]
        d["soil_u"] = [f[k][:].reshape(-1, 3) for k in sorted(f) if k.startswith("displacement_")]
    sp = path[:-3] + "_structure.h5"
    with h5py.File(sp, "r") as f:
        d["blk_x"] = f["coordinates"][:].reshape(-1, 3)
        d["blk_u"] = [f[k][:].reshape(-1, 3) for k in sorted(f) if k.startswith("displacement_")]
    return d


def histories(data, figdir):
    fig, axs = plt.subplots(3, 2, figsize=(10, 10), sharex=True)
    for ax, case in zip(axs.ravel(), CASES):
        d = data.get(case)
        ax.set_title(case)
        if d is None:
            continue
        pts = POINTS[case.split("-")[0]]
        for name, style in (("A", ("0.5", ":", "o")), ("B", ("k", "-", "o"))):
            k = int(np.argmin(np.linalg.norm(d["x"][:, :2] - np.array(pts[name]), axis=1)))
            t = np.r_[0.0, d["t"]]
            ax.plot(t, 1e3 * np.r_[0.0, d["ub"][:, k, 2]], color=style[0], ls=style[1], label=f"{name}$^s$ (soil)")
            ax.plot(t, 1e3 * np.r_[0.0, d["uf"][:, k, 2]], color=style[0], ls="none", marker=style[2], ms=3,
                    mfc="none", label=f"{name}$^f$ (block)")
        if "staggered" in case:
            ax.set_yscale("symlog", linthresh=0.05)
        if "unilateral" in case:
            ax2 = ax.twinx()
            ax2.fill_between(d["t"], 0, d["n_open"], color="tab:red", alpha=0.12, step="pre")
            ax2.set_ylabel("open nodes", color="tab:red")
            ax2.set_ylim(0, len(d["x"]) * 1.05)
        ax.set_ylabel("u_z [mm]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower right")
    for ax in axs[-1]:
        ax.set_xlabel("t [s]")
    fig.suptitle("Vertical displacement at the soil-block interface (A, B: see figures.py)")
    fig.tight_layout()
    fig.savefig(os.path.join(figdir, "histories.png"), dpi=120)
    plt.close(fig)


def snapshots(d, case, figdir, n_panels=6):
    ts = d["soil_t"]
    pick = np.unique(np.linspace(0, len(ts) - 1, n_panels).round().astype(int))
    umax = max(np.abs(u[:, 2]).max() for u in d["soil_u"]) or 1.0
    s = 0.15 / umax
    sx, bx = d["soil_x"], d["blk_x"]
    on = np.abs(sx[:, 1]) < 1e-9
    order = np.argsort(sx[on, 0])
    bon = np.abs(bx[:, 1]) < 1e-9
    fig, axs = plt.subplots(len(pick), 1, figsize=(8, 1.6 * len(pick)), sharex=True)
    for ax, k in zip(np.atleast_1d(axs), pick):
        u = d["soil_u"][k][on][order]
        x0 = sx[on][order]
        ax.plot(x0[:, 0], s * u[:, 2], "k-", lw=1)
        ax.fill_between(x0[:, 0], s * u[:, 2], -0.3, color="0.85")
        ub = d["blk_u"][k][bon]
        xb = bx[bon] + s * ub
        for z in np.unique(np.round(bx[bon, 2], 9)):
            m = np.abs(bx[bon, 2] - z) < 1e-9
            o = np.argsort(bx[bon][m, 0])
            ax.plot(xb[m][o, 0], xb[m][o, 2], color="tab:blue", lw=0.6)
        for x in np.unique(np.round(bx[bon, 0], 9)):
            m = np.abs(bx[bon, 0] - x) < 1e-9
            o = np.argsort(bx[bon][m, 2])
            ax.plot(xb[m][o, 0], xb[m][o, 2], color="tab:blue", lw=0.6)
        ax.set_ylim(-0.3, 0.75)
        ax.set_ylabel(f"t = {ts[k]:.3f} s", fontsize=8)
        ax.set_yticks([])
    np.atleast_1d(axs)[-1].set_xlabel("x [m] (section y = 0)")
    fig.suptitle(f"{case}: displacements x {s:.3g} (max |u_z| soil {1e3 * umax:.3g} mm)")
    fig.tight_layout()
    fig.savefig(os.path.join(figdir, f"snapshots-{case}.png"), dpi=110)
    plt.close(fig)


def findings(data, readme):
    """Table of what the runs show, between <!-- ssi-findings:begin/end --> in the README."""
    cols = ["case", "min u_z block at A [mm]", "max u_z block at B [mm]", "max gap [mm]", "max open nodes",
            "first opening [s]", "open at t_end", "mean u_z block at t_end [mm]", "max |f_fe + f_be| / max |f_be|"]
    rows = []
    for case, d in data.items():
        pts = POINTS[case.split("-")[0]]
        kA = int(np.argmin(np.linalg.norm(d["x"][:, :2] - np.array(pts["A"]), axis=1)))
        kB = int(np.argmin(np.linalg.norm(d["x"][:, :2] - np.array(pts["B"]), axis=1)))
        op = np.nonzero(d["n_open"] > 0)[0]
        fb = np.abs(d["force_be"]).max()
        rows.append([case, f"{1e3 * d['uf'][:, kA, 2].min():.4g}", f"{1e3 * d['uf'][:, kB, 2].max():.4g}",
                     f"{1e3 * d['gap'].max():.3g}", str(int(d["n_open"].max())),
                     f"{d['t'][op[0]]:.4g}" if op.size else "-", str(int(d["n_open"][-1])),
                     f"{1e3 * d['uf'][-1, :, 2].mean():.3g}",
                     f"{np.abs(d['force_fe'] + d['force_be']).max() / fb:.1e}"])
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)] + ["| " + " | ".join(r) + " |" for r in rows]
    text = open(readme).read()
    a, b = "<!-- ssi-findings:begin -->", "<!-- ssi-findings:end -->"
    if a in text:
        import re
        text = re.sub(re.escape(a) + ".*?" + re.escape(b), a + "\n" + "\n".join(lines) + "\n" + b, text, flags=re.S)
        open(readme, "w").write(text)
    print("\n".join(lines))


def main(out, figdir):
    data = {c: load(out, c) for c in CASES}
    data = {c: d for c, d in data.items() if d is not None}
    histories(data, figdir)
    findings(data, os.path.join(figdir, "README.md"))
    for c, d in data.items():
        snapshots(d, c, figdir)
    print(f"[figures] wrote {figdir}/histories.png and {len(data)} snapshot figures")


if __name__ == "__main__":
    main(*sys.argv[1:3])
