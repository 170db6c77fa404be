"""Kernel identities of the time-integrated Stokes kernels (method notes s.6)."""
import numpy as np
import pytest

from petsc_ssi.bem import kernels as K
from petsc_ssi.bem.reference import f1_numeric, t2_numeric

pytestmark = pytest.mark.unit

CP, CS, RHO = 548.0, 316.0, 2000.0
MU = RHO * CS ** 2
NU = (CP ** 2 - 2 * CS ** 2) / (2 * (CP ** 2 - CS ** 2))
DT = 7.5e-4
RNG = np.random.default_rng(1)


def _points(m=6):
    pts = []
    for _ in range(m):
        x = RNG.normal(size=3)
        x *= RNG.uniform(0.1, 8.0) / np.linalg.norm(x)
        n = RNG.normal(size=3)
        pts.append((x, n / np.linalg.norm(n)))
    return pts


@pytest.mark.parametrize("x,n", _points())
def test_heaviside_sum_equals_kelvin(x, n):
    """Sum over all lags of U^l and P^l equals Kelvin's static kernels (1e-10)."""
    r = np.linalg.norm(x)
    g = x / r
    L = int(r / (CS * DT)) + 4
    su = sum(K.lag_u(x, l * DT, DT, CP, CS, RHO) for l in range(1, L + 1))
    sp = sum(K.lag_p(x, n, l * DT, DT, CP, CS, RHO) for l in range(1, L + 1))
    ku = np.zeros((3, 3)); kp = np.zeros((3, 3))
    K.kelvin_u(g, r, NU, MU, ku)
    K.kelvin_p(g, n, r, NU, kp)
    assert np.abs(su - ku).max() <= 1e-10 * np.abs(ku).max()
    assert np.abs(sp - kp).max() <= 1e-10 * np.abs(kp).max()


@pytest.mark.parametrize("x,n", _points())
def test_causality_exact_zeros(x, n):
    """Lags entirely before the P front, and after the S front has passed, are exactly 0."""
    r = np.linalg.norm(x)
    l_first = int(np.floor(r / (CP * DT)))       # l*dt <= r/cp: not reached
    for l in range(1, l_first + 1):
        if l * DT <= r / CP:
            assert not K.lag_u(x, l * DT, DT, CP, CS, RHO).any()
            assert not K.lag_p(x, n, l * DT, DT, CP, CS, RHO).any()
    l_gone = int(np.ceil(r / (CS * DT))) + 2     # (l-2) dt >= r/cs: static already
    for l in range(l_gone + 1, l_gone + 4):
        assert not K.lag_u(x, l * DT, DT, CP, CS, RHO).any()
        p = K.lag_p(x, n, l * DT, DT, CP, CS, RHO)
        # second difference of a linear function: zero up to round-off
        assert np.abs(p).max() <= 1e-12 * np.abs(K.lag_p(x, n, (l_gone - 1) * DT, DT, CP, CS, RHO)).max() + 1e-300


@pytest.mark.parametrize("x,n", _points(4))
def test_f1_against_numeric_time_integration(x, n):
    r = np.linalg.norm(x)
    g = x / r
    for t in np.linspace(0.2, 1.6, 7) * r / CS:
        out = np.zeros((3, 3))
        K.f1_tensor(g, r, t, CP, CS, RHO, out)
        ref = f1_numeric(x, t, CP, CS, RHO)
        assert np.allclose(out, ref, rtol=1e-7, atol=1e-7 * np.abs(ref).max() + 1e-30)


@pytest.mark.parametrize("x,n", _points(4))
def test_traction_against_finite_differences(x, n):
    """Analytic dA/dr, dB/dr and the traction formula vs central differences."""
    r = np.linalg.norm(x)
    g = x / r
    for t in np.array([0.3, 0.7, 0.9, 1.3, 2.5]) * r / CS:
        out = np.zeros((3, 3))
        K.t2_tensor(g, n, r, t, CP, CS, RHO, out)
        ref = t2_numeric(x, n, t, CP, CS, RHO)
        assert np.abs(out - ref).max() <= 1e-6 * np.abs(ref).max() + 1e-30
