"""The independent static solver of a welded rigid disk (petsc_ssi.analytic.disk_static): its
vertical stiffness against the bonded punch's closed form, the incompressible limit (no coupling,
bonded = frictionless), and the reciprocity of its coupling terms."""
import math

import pytest

from petsc_ssi.analytic.disk_static import frictionless_disk, k_z_bonded, square_stiffness, stiffness

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


def test_frictionless_disk_and_torsion_against_the_exact_values():
    """12 rings x 48 sectors, nu = 0.251: the frictionless disk's K_z and K_r within 1 % of
    4 G R / (1 - nu) and 8 G R^3 / (3 (1 - nu)) (measured -0.2 %, -0.6 %), the welded disk's torsion
    within 1 % of 16 G R^3 / 3 (-0.6 %), and welding stiffens: K_z and K_r above the frictionless."""
    nu = 0.251
    kz, kr = frictionless_disk(12, 48, 1.0, nu)
    assert kz / (4 / (1 - nu)) == pytest.approx(1.0, abs=0.01)
    assert kr / (8 / (3 * (1 - nu))) == pytest.approx(1.0, abs=0.01)
    K = stiffness(12, 48, 1.0, nu)
    assert K[3, 3] / (16 / 3) == pytest.approx(1.0, abs=0.01)
    assert K[1, 1] > kz and K[2, 2] > kr


def test_welded_square():
    """The welded square [-1, 1]^2 on 12 x 12 graded cells, nu = 0.251: K_hr = K_rh within 3 %, no
    coupling of the vertical with the rest, and the vertical stiffness within 3 % of Pais and
    Kausel's 4.7 G B / (1 - nu) (measured +1.1 %; +1.9 % extrapolated in
    runs/impedance/graded_static.py)."""
    nu = 0.251
    K = square_stiffness(12, 1.0, nu)
    assert K[2, 0] == pytest.approx(K[0, 2], rel=0.03)
    assert abs(K[1, 0]) < 1e-10 * K[1, 1] and abs(K[1, 2]) < 1e-10 * K[1, 1]
    assert K[1, 1] / (4.7 / (1 - nu)) == pytest.approx(1.0, abs=0.03)
