r"""Lamb's problem under a smooth load pulse: the reference of the smooth-pulse convergence study.

A uniform pressure p0 a(t) on the rectangle [-a, a] x [-b, b] of the surface (pushing down), with a
smooth pulse a(t) that starts and ends at rest. By linearity the surface displacement is the step
response U(t) of the same patch (``pekeris.patch_displacement``: the Pekeris / Lamb point solution
integrated over the rectangle) convolved with the pulse's derivative,

    u(t) = int_0^T U(t - s) a'(s) ds            (a(0) = 0; U(t) = 0 for t <= 0).

The pulse (``bump``): a(t) = sin^4(pi t / T) on [0, T], 0 elsewhere; C^3 (its fourth derivative jumps
at 0 and T), peak 1 at T/2, mean 3/8, harmonics of frequency 1/T and 2/T only on its support
(sin^4 x = 3/8 - cos(2x)/2 + cos(4x)/8): its shortest shear wavelength is lambda_s = c_s T / 2.

U is continuous with kinks (and sqrt-type slopes where the Rayleigh front crosses the patch's corners
and sides), so the convolution is taken on a uniform grid of step T / n (trapezoidal rule in s,
the grid of U aligned with the grid of s: a discrete convolution), then interpolated to the
requested times with a cubic spline (u is as smooth as the pulse). ``n`` sets the accuracy:
tests/analytic/test_pulse.py checks n against 2 n and against adaptive quadrature at single times.
"""
import math

import numpy as np
from scipy.interpolate import CubicSpline

from .pekeris import patch_displacement

__all__ = ["bump", "bump_rate", "bump_table", "pulse_patch_displacement"]


def bump(t, T):
    """a(t) = sin^4(pi t / T) on [0, T], else 0 (dimensionless; t, T in s)."""
    t = np.asarray(t, float)
    s = np.sin(np.pi * np.clip(t, 0.0, T) / T)
    return np.where((t > 0) & (t < T), s ** 4, 0.0)


def bump_rate(t, T):
    """a'(t) [1/s] of ``bump``."""
    t = np.asarray(t, float)
    x = np.pi * np.clip(t, 0.0, T) / T
    return np.where((t > 0) & (t < T), 4.0 * np.sin(x) ** 3 * np.cos(x) * np.pi / T, 0.0)


def bump_table(T, n=2000):
    """(n + 1, 2) rows 't a(t)' of ``bump`` on [0, T] for a '-ssi_load_history table' file. The
    table is linear between rows: its largest deviation from the pulse is max|a''| (T/n)^2 / 8,
    below 2e-6 of the peak for n = 2000."""
    t = np.linspace(0.0, T, n + 1)
    return np.column_stack([t, bump(t, T)])


def pulse_patch_displacement(x, y, t, a, b, p0, cs, cp, rho, T, n=400, gauss=32):
    """Surface displacement (ux, uy, uz) [m] at (x, y, 0) under the pressure p0 bump(t, T) [Pa] on
    [-a, a] x [-b, b] (module docstring); t: array of times [s]. ``n``: convolution steps per pulse
    duration; ``gauss``: Gauss points per piece of the patch integral."""
    tt = np.asarray(t, float)
    ds = T / n
    m = int(math.ceil(max(tt.max(), 0.0) / ds)) + 4
    grid = ds * np.arange(m + 1)
    U = np.array(patch_displacement(x, y, grid, a, b, p0, cs, cp, rho, n=gauss))      # (3, m + 1)
    s = ds * np.arange(n + 1)
    w = np.full(n + 1, ds)
    w[0] = w[-1] = 0.5 * ds
    k = w * bump_rate(s, T)
    out = []
    for c in range(3):
        u = np.convolve(U[c], k)[:m + 1]
        out.append(CubicSpline(grid, u)(tt))
    return tuple(np.where(tt > 0, o, 0.0) for o in out)
