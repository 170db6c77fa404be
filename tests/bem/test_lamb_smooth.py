"""Lamb's problem under a smooth load pulse (issue 46): the BEM converges at second order.

The two coarsest levels of runs/pekeris/convergence_smooth.py (h = 3 m and 1.5 m, dt = 0.237 h / c_s,
a sin^4 pulse of T = 0.03 s on the square [-3, 3]^2 m; shear wavelength of the pulse's top harmonic
lambda_s = c_s T / 2 = 4.74 m) at its near receiver r = 5 m, on a smaller surface (30 m x 30 m
instead of 48 m x 48 m) and a window that ends when the Rayleigh pulse from the far edge of the load
has passed r = 5 m (t_w = 0.0575 s). The reference is the Pekeris patch step response convolved with
the pulse's derivative (petsc_ssi.analytic.pulse). The full study (three levels, r = 5 m and 15 m,
the truncation check) is runs/pekeris/convergence_smooth.py and its slow-tier test below.
"""
import math

import numpy as np
import pytest

from helpers import run_bem
from petsc_ssi.analytic.pekeris import arrivals
from petsc_ssi.analytic.pulse import bump_table, pulse_patch_displacement

pytestmark = pytest.mark.run

CP, CS, RHO, P0, A, T = 548.0, 316.0, 2000.0, 1000.0, 3.0, 0.03
BETA = CS * 7.5e-4          # c_s dt / h of the paper's mesh (h = 1 m, dt = 7.5e-4 s)
R = 5.0


def _window(r):
    return (r + A) * arrivals(0.25)[2] / CS + T        # (r + A) / c_R + T


def _errors(tmp_path, h, half):
    table = tmp_path / "bump.txt"
    np.savetxt(table, bump_table(T))
    out = tmp_path / f"h{h:g}.h5"
    tw = _window(R)
    run_bem(cp=CP, cs=CS, rho=RHO, dt=BETA * h / CS, t_end=tw + 0.003, mesh="grid", mesh_size=f"{2 * half:g},{2 * half:g}",
            mesh_h=h, mesh_patch=f"{A:g},{A:g}", symmetry="x=sym,y=sym", load_group="load", load_p0=P0,
            load_history="table", load_table=str(table), scheme="stabilized", receivers=f"{R:g},0,0",
            output=str(out), output_stride=0, warn_beta=0)
    import h5py
    with h5py.File(out, "r") as f:
        t, u = f["receivers/t"][:], f["receivers/u"][:, 0, :]
    m = t <= tw + 1e-12
    ux, _, uz = pulse_patch_displacement(R, 0.0, t[m], A, A, P0, CS, CP, RHO, T)
    return (np.linalg.norm(u[m, 0] - ux) / np.linalg.norm(ux), np.linalg.norm(u[m, 2] - uz) / np.linalg.norm(uz))


def test_smooth_pulse_second_order_at_5m(tmp_path):
    """Halving h and dt: both components' errors fall at an observed order above 1.7 (measured
    2.53 radial, 1.91 vertical on this surface, the same to two digits on the study's 48 m surface;
    the study's next pair, h = 1.5 -> 1 m, gives 2.24 / 2.25), and the finer level is within 3 %
    (measured 2.0 % radial, 1.4 % vertical)."""
    e3, e15 = _errors(tmp_path, 3.0, 15.0), _errors(tmp_path, 1.5, 15.0)
    orders = [math.log(a / b) / math.log(2.0) for a, b in zip(e3, e15)]
    assert all(p > 1.7 for p in orders), (e3, e15, orders)
    assert max(e15) < 0.03, e15


def _study_module():
    from helpers import run_script
    return run_script("runs", "pekeris", "convergence_smooth.py")


# slow tier: the full study's three levels at r = 5 m and 15 m on the 48 m surface (about 6 min on
# 2 ranks of an idle 2-core machine, 11 GB at h = 1 m); the default tier keeps the two coarse levels
# at 5 m above
@pytest.mark.slow
def test_smooth_pulse_full_study(tmp_path):
    """runs/pekeris/convergence_smooth.py's levels h = 3, 1.5, 1 m: the last pair converges at an
    observed order >= 1.8 at both receivers and components (measured 2.24 / 2.25 at 5 m, 1.98 / 1.98
    at 15 m; 2.04 / 2.40 at 15 m in the diffraction-free window), and h = 1 m is within 2 %."""
    mod = _study_module()
    levels = list(mod.LEVELS)
    errs, clean = {}, {}
    for h in levels:
        t, u = mod.run_level(h, mod.D, str(tmp_path), 2)[:2]
        errs[h], clean[h] = mod.errors(t, u), mod.errors(t, u, clean=True)
    for table in (errs, clean):
        for key, ords in mod.orders(levels, table).items():
            assert ords[-1] >= 1.8, (key, ords, {h: table[h][key] for h in levels})
    assert max(errs[levels[-1]].values()) < 0.02, errs[levels[-1]]
