"""Error measures against the analytic Lamb/Pekeris solution.

Definition used throughout (tests, demo, benchmark tables): for a receiver at
distance r, with u~ = pi mu u r / P and tau = c_s t / r, the relative L2 error
over tau in [0, tau_max] is

  e = || u~_BEM - u~_ref ||_2 / || u~_ref ||_2

on the BEM time samples in that window, where u~_ref is the Pekeris solution
integrated over the same loaded rectangle (not the point load), evaluated at
the same times. Vertical: the z component; horizontal: the radial component.
"""
import numpy as np


def lamb_errors(path, tau_max=2.5):
    """[(r, e_vertical, e_radial)] for every receiver of an output file."""
    import h5py
    from .analytic.pekeris import patch_displacement
    with h5py.File(path, "r") as f:
        pts, t, u = f["receivers/points"][:], f["receivers/t"][:], f["receivers/u"][:]
        at = dict(f.attrs)
    cp, cs, rho = float(at["cp"]), float(at["cs"]), float(at["rho"])
    p0 = float(at["load_p0"])
    a, b = (float(v) for v in str(at["load_patch"]).split(","))
    out = []
    for k, p in enumerate(pts):
        r = float(np.hypot(p[0], p[1]))
        m = cs * t / r <= tau_max
        ux, uy, uz = patch_displacement(p[0], p[1], t[m], a, b, p0, cs, cp, rho)
        er = np.array([p[0], p[1]]) / r
        ref_r = ux * er[0] + uy * er[1]
        bem_r = u[m, k, :2] @ er
        ev = np.linalg.norm(u[m, k, 2] - uz) / np.linalg.norm(uz)
        eh = np.linalg.norm(bem_r - ref_r) / np.linalg.norm(ref_r)
        out.append((r, float(ev), float(eh)))
    return out
