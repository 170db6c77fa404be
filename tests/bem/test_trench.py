"""An open trench between a vertical surface source and receivers behind it (issue 42, item 5;
``runs/trench/trench.py``, whose functions these tests run): the trench is ``-ssi_mesh pit`` with a
long narrow opening off the centre (``-ssi_mesh_params a=,b=,d=,x=``), the source a 3-cycle tone burst
of Rayleigh wavelength lambda_R = 4 m, the amplitude reduction factor ARF the peak |u_z| behind the
trench over the peak without it (the same ground mesh).

What a wrong trench would fail: a trench that did not scatter (normals, free terms or walls wrong)
leaves ARF near 1; the published trend (Woods 1968; Segol, Lee & Abel 1978) is ARF well below 1/2
once d / lambda_R exceeds about 0.6, and a reduction that grows with the depth.
Measured (runs/trench/README.md)."""

import numpy as np
import pytest

from helpers import run_script

pytestmark = pytest.mark.run


def script():
    return run_script("runs", "trench", "trench.py")


def test_the_generator_places_a_trench_off_the_centre():
    """-ssi_mesh pit with x=: the opening [x - a, x + a] x [-b, b], walls and bottom closed, accepted by
    check_excavation; an opening that reaches the ground's edge is refused."""
    from petsc_ssi.mesh.surface import pit, check_excavation
    from petsc_ssi.petsc import SSIError
    m = pit(14.0, 8.0, 1.0, 0.5, 3.0, 2.0, xc=-2.5)
    check_excavation(m, "trench")
    bottom = m.nodes[np.unique(m.cells[m.groups["bottom"]])]
    assert np.allclose(bottom[:, 2], -2.0)
    assert bottom[:, 0].min() == -3.0 and bottom[:, 0].max() == -2.0 and np.ptp(bottom[:, 1]) == 6.0
    walls = m.nodes[np.unique(m.cells[m.groups["walls"]])]
    assert walls[:, 2].min() == -2.0 and walls[:, 2].max() == 0.0
    with pytest.raises(SSIError, match="inside the ground"):
        pit(14.0, 8.0, 1.0, 0.5, 3.0, 2.0, xc=-6.6)


def test_a_deep_trench_screens_the_motion_behind_it(tmp_path):
    """SMALL (a 14 m x 8 m ground, trench 1 m wide, 6 m long, 3 m deep: d / lambda_R = 0.75; receivers
    1 m to 4 m behind it): the flat run's wave travels at the Rayleigh speed within 10 % (so lambda_R is
    what the source was tuned to; measured 284 m/s against 290.6 m/s), and behind the trench the mean
    ARF is under 0.5 and every receiver's under 0.6 (Woods: 0.25 - 0.5 at d / lambda_R 0.6 - 1;
    measured mean 0.20, largest 0.28)."""
    s = script()
    rows, (t, flat, c) = s.arf(s.SMALL, (3.0,), str(tmp_path / "t.h5"))
    assert abs(c / s.rayleigh_speed() - 1) < 0.10, c
    assert np.abs(flat[:, :, 2]).max() > 0
    d, ratio, mean, lo, hi = rows[0]
    assert ratio == 0.75 and 0 < lo and mean < 0.5 and hi < 0.6, rows


# slow tier: the sweep of runs/trench/README.md (6 depths on the 20 m x 12 m ground, about 2 minutes;
# the one deep trench on the small ground stays)
@pytest.mark.slow
def test_the_reduction_grows_with_the_depth(tmp_path):
    """A shallow trench (d / lambda_R = 0.125) hardly screens (mean ARF above 0.7; measured 0.86); from
    d / lambda_R = 0.5 on, the mean ARF lies between 0.1 and 0.5 (Woods: 0.25 - 0.5 at 0.6 - 1; measured
    0.21 - 0.26), the deepest at least 0.5 below the shallowest, and no trench's mean more than 0.05 above
    a shallower one's (the plateau's scatter: measured +0.04 from 0.375 to 0.5)."""
    s = script()
    rows, (_, _, c) = s.arf(s.SWEEP, (0.5, 1.0, 1.5, 2.0, 3.0, 4.0), str(tmp_path / "t.h5"))
    assert abs(c / s.rayleigh_speed() - 1) < 0.10, c
    mean = np.array([r[2] for r in rows])
    assert mean[0] > 0.7 and mean[0] > mean[-1] + 0.5, rows
    assert np.all(mean - np.minimum.accumulate(mean) <= 0.05), rows
    assert all(0.1 < r[2] < 0.5 for r in rows if r[1] >= 0.5), rows
