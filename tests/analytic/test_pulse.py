"""The smooth-pulse Lamb reference (petsc_ssi.analytic.pulse): the pulse, its table, and the
convolution of the Pekeris patch step response against adaptive quadrature and against itself at
twice the resolution."""
import numpy as np
import pytest
from scipy import integrate

from petsc_ssi.analytic.pekeris import patch_displacement
from petsc_ssi.analytic.pulse import bump, bump_rate, bump_table, pulse_patch_displacement

pytestmark = pytest.mark.unit

CP, CS, RHO, P0, A, T = 548.0, 316.0, 2000.0, 1000.0, 3.0, 0.03


def test_bump_rate_and_table():
    """a' is the derivative of a (central differences to 1e-6 of max|a'|); the 2000-row table
    (linear between rows) stays within 2e-6 of the pulse; a(T/2) = 1, zero outside (0, T)."""
    t = np.linspace(-0.01, 0.04, 5001)
    d = 1e-7
    fd = (bump(t + d, T) - bump(t - d, T)) / (2 * d)
    assert np.abs(fd - bump_rate(t, T)).max() < 1e-6 * np.abs(bump_rate(t, T)).max()
    tab = bump_table(T)
    tt = np.linspace(0, T, 100001)
    assert np.abs(np.interp(tt, tab[:, 0], tab[:, 1]) - bump(tt, T)).max() < 2e-6
    assert bump(T / 2, T) == pytest.approx(1.0) and bump(-1e-3, T) == 0.0 and bump(T + 1e-3, T) == 0.0


def test_convolution_against_quadrature_and_resolution():
    """The grid convolution equals scipy's adaptive quadrature of int U(t - s) a'(s) ds to 1e-4 of
    the peak (r = 15 m vertical with the Rayleigh pulse passing, t = 0.06 s; r = 5 m radial at
    t = 0.03 s), and the default resolution (n = 400) equals n = 800 to 3e-5 (relative L2 over
    0..0.07 s at r = 15 m, both components)."""
    t = np.linspace(0.0, 0.07, 71)
    u4 = np.array(pulse_patch_displacement(15.0, 0.0, t, A, A, P0, CS, CP, RHO, T))
    u8 = np.array(pulse_patch_displacement(15.0, 0.0, t, A, A, P0, CS, CP, RHO, T, n=800))
    for c in (0, 2):
        assert np.linalg.norm(u4[c] - u8[c]) < 3e-5 * np.linalg.norm(u8[c]), c
    assert np.all(u4[1] == 0.0)          # the receiver on the x axis: no y component
    for r, tq, c in ((15.0, 0.06, 2), (5.0, 0.03, 0)):
        v = pulse_patch_displacement(r, 0.0, np.array([tq]), A, A, P0, CS, CP, RHO, T)[c][0]
        f = lambda s: patch_displacement(r, 0.0, np.array([tq - s]), A, A, P0, CS, CP, RHO)[c][0] * bump_rate(s, T)
        q = integrate.quad(f, 0.0, T, limit=200, epsrel=1e-7)[0]
        peak = np.abs(pulse_patch_displacement(r, 0.0, t, A, A, P0, CS, CP, RHO, T)[c]).max()
        assert abs(v - q) < 1e-4 * peak, (r, c, v, q)
