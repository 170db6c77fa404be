"""Plots (matplotlib, Agg): receiver histories in the paper's dimensionless
form u~ = pi mu u r / P against tau = c_s t / r (Figs. 3-4), with the Pekeris
solution for the same loaded patch when the run was a Lamb problem."""
import os

import numpy as np


def _mpl():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def lamb_reference(points, t, cp, cs, rho, a, b, p0):
    """Pekeris patch solution at the receivers (None if unavailable)."""
    try:
        from .analytic.pekeris import patch_displacement
    except ImportError:
        return None
    out = np.zeros((len(t), len(points), 3))
    for k, p in enumerate(points):
        ux, uy, uz = patch_displacement(p[0], p[1], t, a, b, p0, cs, cp, rho)
        out[:, k] = np.stack([ux, uy, uz], 1)
    return out


def receiver_plot(path, cfg=None, png=None, reference=True):
    """PNG of receiver histories beside ``path`` (rank 0 only)."""
    import h5py
    plt = _mpl()
    with h5py.File(path, "r") as f:
        pts, t, u = f["receivers/points"][:], f["receivers/t"][:], f["receivers/u"][:]
        at = dict(f.attrs)
    cp, cs, rho = float(at.get("cp", 548)), float(at.get("cs", 316)), float(at.get("rho", 2000))
    p0 = float(at.get("load_p0", 0.0))
    mu = rho * cs ** 2
    patch = at.get("load_patch", None)
    ref = None
    if reference and patch is not None and p0 != 0.0:
        a, b = (float(v) for v in str(patch).split(","))
        tf = np.linspace(t[0] * 0.5, t[-1], 400)
        ref = lamb_reference(pts, tf, cp, cs, rho, a, b, p0)
        P = p0 * 4 * a * b
    else:
        P = p0 if p0 else 1.0
    fig, axs = plt.subplots(len(pts), 2, figsize=(10, 3.2 * len(pts)), squeeze=False)
    for k, p in enumerate(pts):
        r = float(np.hypot(p[0], p[1])) or 1.0
        er = np.array([p[0], p[1], 0.0]) / r
        tau = cs * t / r
        scale = np.pi * mu * r / P
        ur = u[:, k] @ er
        for j, (lab, val) in enumerate((("radial", ur), ("vertical", u[:, k, 2]))):
            ax = axs[k, j]
            ax.plot(tau, scale * val, "k-", lw=1.5, label="petsc_ssi BEM")
            if ref is not None:
                rr = ref[:, k] @ er if j == 0 else ref[:, k, 2]
                ax.plot(cs * tf / r, scale * rr, color="0.6", lw=1.2, label="Pekeris (same patch)")
            ax.set_xlabel(r"$\tau = c_s t / r$")
            ax.set_ylabel(r"$\tilde u = \pi\mu u r / P$")
            ax.set_title(f"{lab}, r = {r:g} m")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
    fig.tight_layout()
    png = png or os.path.splitext(path)[0] + ".png"
    fig.savefig(png, dpi=120)
    plt.close(fig)
    return png
