"""The element integrals of a regular pair in the plane z = 0 (quadrature.integrate_plane, the
geometry of each element's Gauss points computed once by plane_points) against the general kernel
(quadrature.integrate_pair): the same numbers bit for bit in every entry of the flat patterns
(bsr.PATTERNS: H's 4, G's 5), and the general kernel's other entries exactly zero, on distorted
nine-node elements (curved, skewed, either orientation), collocation points near and far, the
near pairs' extra subdivisions, a kernel time between lags (the interpolating matrices) and with
and without the displacement kernel, and the displacement kernel alone (want_p False). The assembly path that chooses between them is run whole in
tests/bem/test_flat_pattern.py (the flat pattern against -ssi_lag_pattern full)."""
import numpy as np
import pytest

from petsc_ssi.bem.bsr import positions
from petsc_ssi.bem.quadrature import integrate_pair, integrate_plane, plane_points
from petsc_ssi.bem.packs import wave

pytestmark = pytest.mark.unit

CP, CS, RHO, NU = 400.0, 200.0, 2000.0, 1.0 / 3.0
DT = 2e-3


def _element(rng, h, flip):
    """A nine-node element of size ~h in z = 0 with curved, skewed sides (mid-side and centre nodes
    moved in the plane), optionally of the opposite orientation (normal -z)."""
    xi = np.array([-1., 1., 1., -1., 0., 1., 0., -1., 0.])
    eta = np.array([-1., -1., 1., 1., -1., 0., 1., 0., 0.])
    X = np.zeros((9, 3))
    X[:, 0] = 0.5 * h * (xi + 0.15 * eta)
    X[:, 1] = 0.5 * h * eta
    X[4:, :2] += rng.uniform(-0.08, 0.08, (5, 2)) * h
    if flip:
        X[:, 1] *= -1.0
    return X


@pytest.mark.parametrize("want_u", [True, False])
@pytest.mark.parametrize("toff", [0.0, 0.37 * DT])
def test_plane_kernel_equals_the_general_kernel_bit_for_bit(want_u, toff):
    rng = np.random.default_rng(3 + int(want_u) + int(toff > 0))
    hp, hq = positions(4)
    gp, gqi = positions(5)
    keepH = np.zeros((3, 3), bool); keepH[hp, hq] = True
    keepG = np.zeros((3, 3), bool); keepG[gp, gqi] = True
    gq, gw = np.polynomial.legendre.leggauss(2)
    h, L = 0.8, 40
    checked = 0
    for case in range(12):
        X = _element(rng, h, flip=case % 2 == 1)
        # collocation points: beside the element (near: more subdivisions), a few sizes away, far
        d = [0.05, 0.3, 1.5, 6.0][case % 4] * h
        ang = rng.uniform(0, 2 * np.pi)
        xc = np.array([X[8, 0] + (0.5 * h + d) * np.cos(ang), X[8, 1] + (0.5 * h + d) * np.sin(ang), 0.0])
        ns = 4 if case % 4 > 1 else [8, 16][case % 2]
        lo, hi = 1, L
        Ub, Pb = np.zeros((L, 9, 3, 3)), np.zeros((L, 9, 3, 3))
        n_gen = integrate_pair(xc, X, -1, ns, lo, hi, wave(DT, CP, CS, RHO, NU, toff), gq, gw, Ub, Pb, want_u)
        sub, pts, Ntab = np.zeros((ns * ns, 4)), np.zeros((ns * ns * 4, 4)), np.zeros((ns * ns * 4, 9))
        plane_points(X, ns, gq, gw, sub, pts, Ntab)
        P, U = np.zeros((L, 9, 4)), np.zeros((L, 9, 5))
        n_pl = integrate_plane(xc, sub, pts, Ntab, 4, lo, hi, wave(DT, CP, CS, RHO, NU, toff), P, U, want_u, True)
        assert n_pl == n_gen > 0
        assert np.abs(P).max() > 0
        assert np.array_equal(P, Pb[:, :, hp, hq])                  # bit for bit
        assert not Pb[:, :, ~keepH].any()                           # the rest: exact zeros
        if want_u:
            assert np.abs(U).max() > 0
            assert np.array_equal(U, Ub[:, :, gp, gqi])
            assert not Ub[:, :, ~keepG].any()
            # G alone (want_p False: the area loads' and the toeplitz G side's integrals): the same U, P not touched
            P2, U2 = np.full((L, 9, 4), 7.0), np.zeros((L, 9, 5))
            n_u = integrate_plane(xc, sub, pts, Ntab, 4, lo, hi, wave(DT, CP, CS, RHO, NU, toff), P2, U2, True, False)
            assert n_u == n_pl
            assert np.array_equal(U2, U)
            assert (P2 == 7.0).all()
        else:
            assert not U.any()
        checked += 1
    assert checked == 12
