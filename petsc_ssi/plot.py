"""Plots (matplotlib, Agg): receiver histories. A Lamb problem (a BEM half-space run loaded on a
surface patch, every receiver off the load's axis, displacements) in the paper's dimensionless form
u~ = pi mu u r / P against tau = c_s t / r (Figs. 3-4), with the Pekeris solution for the same
loaded patch; anything else (a structure's or a coupled run's output, velocities, accelerations,
rotations, a receiver at r = 0) as the stored quantity in its own units against t [s], the x, y and
z components of each receiver."""
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


UNITS = {"u": "m", "velocity": "m/s", "acceleration": "m/s^2", "rotation": "rad"}
NAMES = {"u": "displacement", "velocity": "velocity", "acceleration": "acceleration", "rotation": "rotation"}


def is_lamb(attrs, points, series="receivers/u"):
    """Whether the dimensionless Lamb form fits: a BEM half-space run with a loaded surface patch,
    displacements, every receiver at r = sqrt(x^2 + y^2) > 0 (r is the form's length scale)."""
    return (series.strip("/") == "receivers/u" and str(attrs.get("problem", "")) == "bem"
            and float(attrs.get("load_p0", 0.0)) != 0.0 and attrs.get("load_patch", None) is not None
            and len(points) > 0 and float(np.hypot(points[:, 0], points[:, 1]).min()) > 0.0)


def receiver_plot(path, cfg=None, png=None, reference=True, series="receivers/u"):
    """PNG of receiver histories beside ``path`` (rank 0 only): the Lamb form where ``is_lamb``,
    else ``series`` against t [s] (``series_plot``)."""
    import h5py
    with h5py.File(path, "r") as f:
        pts, t = f["receivers/points"][:], f["receivers/t"][:]
        at = dict(f.attrs)
        lamb = is_lamb(at, pts, series)
        u = f["receivers/u"][:] if lamb else None
    if not lamb:
        return series_plot(path, series, png)
    plt = _mpl()
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


def series_plot(path, series="receivers/u", png=None):
    """PNG of a receiver series (``GROUP/NAME`` of shape (K, R, 3) or (K, 3), with GROUP/t) against
    t [s]: one panel per receiver, its x, y, z components, in the quantity's unit (the dataset's
    'unit' attribute, else m, m/s, m/s^2, rad by name); receivers without rotations (not at a frame
    or shell node) are said so in their panel."""
    import h5py
    series = series.strip("/")
    grp, _, name = series.rpartition("/")
    with h5py.File(path, "r") as f:
        if series not in f:
            raise ValueError(f"{path} holds no series {series}")
        t = f[(grp + "/t") if grp else "t"][:]
        x = f[series][:]
        unit = f[series].attrs.get("unit", UNITS.get(name, ""))
        unit = unit.decode() if isinstance(unit, bytes) else str(unit)
        pts = f[grp + "/points"][:] if grp and grp + "/points" in f else None
        has_rot = f[grp + "/has_rotation"][:] if name == "rotation" and grp + "/has_rotation" in f else None
        problem = str(f.attrs.get("problem", ""))
    if x.ndim == 2:
        x = x[:, None, :]
    plt = _mpl()
    R = x.shape[1]
    fig, axs = plt.subplots(R, 1, figsize=(9, 2.8 * R), squeeze=False, sharex=True)
    label = NAMES.get(name, name)
    for k in range(R):
        ax = axs[k, 0]
        where = f"receiver {k}" + (f" at ({pts[k, 0]:g}, {pts[k, 1]:g}, {pts[k, 2]:g}) m" if pts is not None else "")
        if has_rot is not None and not bool(has_rot[k]):
            ax.text(0.5, 0.5, "no rotation here (not at a frame or shell node)", ha="center", va="center",
                    transform=ax.transAxes)
        else:
            for j, c in enumerate("xyz"[:x.shape[2]]):
                ax.plot(t, x[:, k, j], lw=1.2, label=f"{c}")
            ax.legend(fontsize=8)
        ax.set_ylabel(f"{label} [{unit}]" if unit else label)
        ax.set_title(f"{os.path.basename(path)} ({problem or 'run'}): {series}, {where}", fontsize=9)
        ax.grid(alpha=0.3)
    axs[-1, 0].set_xlabel("t [s]")
    fig.tight_layout()
    png = png or os.path.splitext(path)[0] + ".png"
    fig.savefig(png, dpi=120)
    plt.close(fig)
    return png
