"""The structure's integrators near the Nyquist frequency (issue 46): steady response to a harmonic
load and free vibration of one oscillator, from the closed forms of petsc_ssi/fem/integrator_response.py
(checked against the integrator classes by tests/fem/test_integrator_response.py).

Writes, beside the BEM's stability maps (runs/stability/):
  integrator_response.csv   amplification (discrete / exact steady displacement) against f dt
  integrator_free.csv       spectral radius and period elongation against omega dt
  integrator_response.png   the three panels

    .venv/bin/python runs/integrators/response.py            (a few seconds)
"""
import csv
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, ROOT)
from petsc_ssi.fem import integrator_response as ir  # noqa: E402

OUT = os.path.join(ROOT, "runs", "stability")
DT = 5e-3                               # for the Hz axis: the paper's step
OSC = ((2 * np.pi * 5.0 * DT, 0.02), (2 * np.pi * 30.0 * DT, 0.02))    # 5 Hz and 30 Hz modes at 5 ms, 2 %
COLORS = {"green": "tab:green", "newmark": "tab:blue", "midpoint": "tab:orange"}


def tables():
    x = np.round(np.linspace(0.005, 0.495, 99), 6)
    rows = []
    for xi in x:
        row = {"f_dt [cycles/step]": xi, "f at dt 5 ms [Hz]": xi / DT}
        for k in ir.SCHEMES:
            row[f"stiff {k} [-]"] = float(ir.stiff_amplification(k, xi))
        for W, z in OSC:
            for k in ir.SCHEMES:
                row[f"omega_dt {W:.4g} zeta {z:g} {k} [-]"] = abs(ir.steady_ratio(k, W, xi, z))
        rows.append(row)
    free = []
    for W in np.round(np.linspace(0.05, 3.0, 60), 6):
        row = {"omega_dt [rad/step]": W}
        for k in ir.SCHEMES:
            rho, per = ir.free_vibration(k, W)
            row[f"{k} spectral radius [-]"] = rho
            row[f"{k} period elongation T_h/T [-]"] = per
        free.append(row)
    return rows, free


def write(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        for r in rows:
            w.writerow({k: f"{v:.6g}" for k, v in r.items()})


def plot(rows, free, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    x = np.array([r["f_dt [cycles/step]"] for r in rows])
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.6))
    ax = axs[0]
    for k in ir.SCHEMES:
        ax.semilogy(x, [r[f"stiff {k} [-]"] for r in rows], color=COLORS[k], label=k)
    ax.axhline(1.0, color="k", lw=0.8, ls=":")
    ax.axhline(1.0 + ir.SAFE_TOL, color="0.5", lw=0.8, ls="--", label=f"1 + {ir.SAFE_TOL:g}")
    ax.set_title("stiff mode (omega >> 2 pi f): steady / static")
    ax.set_xlabel("load frequency f dt [cycles/step]")
    ax.set_ylabel("amplification, discrete / exact [-]")
    sec = ax.secondary_xaxis("top", functions=(lambda v: v / DT, lambda v: v * DT))
    sec.set_xlabel("f at dt = 5 ms [Hz]")
    ax.legend()
    ax = axs[1]
    for (W, z), ls in zip(OSC, ("-", "--")):
        for k in ir.SCHEMES:
            ax.semilogy(x, [r[f"omega_dt {W:.4g} zeta {z:g} {k} [-]"] for r in rows], color=COLORS[k], ls=ls,
                        label=f"{k}, omega dt {W:.3g} ({W / (2 * np.pi * DT):.0f} Hz at 5 ms)")
    ax.axhline(1.0, color="k", lw=0.8, ls=":")
    ax.set_title("oscillator, zeta = 2 %: steady / exact")
    ax.set_xlabel("load frequency f dt [cycles/step]")
    ax.set_ylabel("amplification, discrete / exact [-]")
    sec = ax.secondary_xaxis("top", functions=(lambda v: v / DT, lambda v: v * DT))
    sec.set_xlabel("f at dt = 5 ms [Hz]")
    ax.legend(fontsize=7)
    ax = axs[2]
    W = np.array([r["omega_dt [rad/step]"] for r in free])
    for k, ls in zip(ir.SCHEMES, ("-", "--", ":")):
        ax.plot(W, [r[f"{k} period elongation T_h/T [-]"] for r in free], color=COLORS[k], ls=ls,
                label=f"{k}: T_h / T")
        ax.plot(W, [r[f"{k} spectral radius [-]"] for r in free], color=COLORS[k], ls=ls, lw=0.8,
                label=f"{k}: spectral radius")
    ax.set_title("free vibration (undamped)")
    ax.set_xlabel("omega dt [rad/step]")
    ax.set_ylabel("period elongation T_h/T, spectral radius [-]")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    rows, free = tables()
    write(os.path.join(OUT, "integrator_response.csv"), rows)
    write(os.path.join(OUT, "integrator_free.csv"), free)
    plot(rows, free, os.path.join(OUT, "integrator_response.png"))
    for xi in (0.1, 0.25, 0.39, 0.45):
        print(f"f dt {xi:.2f} ({xi / DT:.0f} Hz at 5 ms): stiff amplification "
              + ", ".join(f"{k} x{float(ir.stiff_amplification(k, xi)):.3g}" for k in ir.SCHEMES)
              + f"; 1/cos^2(pi f dt) = {1 / np.cos(np.pi * xi) ** 2:.3g}")
    print("safe band (stiff amplification <= 1.05): " + ", ".join(f"{k} f dt <= {ir.safe_band(k):.4g} "
          f"({ir.safe_band(k) / DT:.3g} Hz at 5 ms)" for k in ir.SCHEMES))
    for W in (0.5, 1.0, 2.0):
        print(f"omega dt {W}: period elongation {ir.free_vibration('green', W)[1]:.4f}, spectral radius "
              f"{ir.free_vibration('green', W)[0]:.6f} (all three schemes: the same R)")
    print(f"wrote {OUT}/integrator_response.csv, integrator_free.csv, integrator_response.png")


if __name__ == "__main__":
    main()
