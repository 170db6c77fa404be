"""Stabilised scheme (eq. 7): no growth over 420 steps for beta = c_s dt / l
in the paper's range, and the late-time displacement under the load settles
to the static value of the same truncated surface.

Static reference: Love's solution for the centre of a uniformly loaded
square on the half-space (petsc_ssi.analytic.boussinesq_rectangle); the
truncated 8 m x 8 m surface (the mesh ends 3 m beyond the load) costs some
accuracy, so the tolerance is 6% (measured: see the assertion message).
"""
import numpy as np
import pytest

from helpers import run_bem
from petsc_ssi.analytic.pekeris import boussinesq_rectangle

pytestmark = pytest.mark.run

CP, CS, RHO = 548.0, 316.0, 2000.0
L_NODE = 0.5   # node spacing of 1 m nine-node elements


@pytest.mark.parametrize("beta", [0.3, 0.55, 0.8])
def test_stabilized_no_growth_and_static_limit(tmp_path, beta):
    dt = beta * L_NODE / CS
    n = 420
    res = run_bem(mesh_size="8,8", mesh_h=1.0, mesh_patch="1,1", load_group="load", load_p0=1000,
                  symmetry="x=sym,y=sym", dt=dt, t_end=n * dt, receivers="0,0,0;2,0,0",
                  output_stride=0, warn_beta=0, output=tmp_path / "s.h5")
    un = res["unorm"]
    assert len(un) == n and np.all(np.isfinite(un))
    late, mid = un[-100:], un[-250:-150]
    # no growth: the last 100 steps are within 1% of the steps 170..270
    assert late.max() <= 1.01 * mid.max(), (late.max(), mid.max())
    assert np.ptp(late) <= 0.01 * late.max()
    mu = RHO * CS ** 2
    nu = (CP ** 2 - 2 * CS ** 2) / (2 * (CP ** 2 - CS ** 2))
    w0 = boussinesq_rectangle(0.0, 0.0, 1.0, 1.0, 1000.0, mu, nu)[2]
    uz = res["u"][-1, 0, 2]
    assert abs(uz - w0) <= 0.06 * abs(w0), (uz, w0, (uz - w0) / w0)
