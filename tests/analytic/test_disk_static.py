"""The independent static solver of a welded rigid disk (petsc_ssi.analytic.disk_static): its
vertical stiffness against the bonded punch's closed form, the incompressible limit (no coupling,
bonded = frictionless), and the reciprocity of its coupling terms."""
import math

import pytest

from petsc_ssi.analytic.disk_static import k_z_bonded, stiffness

pytestmark = pytest.mark.unit


def test_vertical_stiffness_and_coupling_at_nu_one_third():
    """nu = 1/3, 6 rings x 24 sectors: K_z within 1 % of 4 G R ln(3 - 4 nu) / (1 - 2 nu) (measured
    -0.8 %), K_x within 2 % of 8 G R / (2 - nu) (+0.1 %), K_r within 4 % above the frictionless
    8 G R^3 / (3 (1 - nu)) (+1.0 %: welding stiffens), and the coupling K_hr = K_rh (1 %) near
    -0.08 R K_x (measured -0.0803; -0.0812 extrapolated in runs/impedance/disk_coupling_static.py)."""
    nu = 1.0 / 3.0
    K = stiffness(6, 24, 1.0, nu)
    assert K[1, 1] / k_z_bonded(1.0, nu) == pytest.approx(1.0, abs=0.01)
    assert K[0, 0] / (8 / (2 - nu)) == pytest.approx(1.0, abs=0.02)
    assert 1.0 <= K[2, 2] / (8 / (3 * (1 - nu))) <= 1.04
    assert K[2, 0] == pytest.approx(K[0, 2], rel=0.01)
    assert -0.085 < K[2, 0] / K[0, 0] < -0.076, K[2, 0] / K[0, 0]
    assert abs(K[1, 0]) < 1e-10 * K[1, 1] and abs(K[1, 2]) < 1e-10 * K[1, 1]     # no vertical-horizontal coupling


def test_incompressible_limit_has_no_coupling():
    """nu = 1/2: the Boussinesq-Cerruti kernel has no (1 - 2 nu) term, so the coupling vanishes to
    round-off and the vertical stiffness approaches the punch's 8 G R (bonded = frictionless)."""
    K = stiffness(6, 24, 1.0, 0.5)
    assert abs(K[2, 0]) < 1e-12 * math.sqrt(K[0, 0] * K[2, 2])
    assert K[1, 1] / 8.0 == pytest.approx(1.0, abs=0.01)
