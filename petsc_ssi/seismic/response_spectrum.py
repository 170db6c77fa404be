"""Earthquake response spectra by exact piecewise-linear integration (numpy only).

Oscillator and input
    A linear SDOF oscillator of period T (omega = 2 pi / T) and damping ratio zeta on
    a ground with acceleration a_g(t) [m/s^2]:  u'' + 2 zeta omega u' + omega^2 u = -a_g,
    u the displacement relative to the ground, at rest at t[0].  a_g is taken as the
    piecewise-linear interpolant of the samples (uniform or non-uniform time grid).
    The recurrence below is exact for that input, so the response AT THE SAMPLES does
    not depend on the step: coarsening a grid on which a_g is still piecewise linear
    changes nothing (up to rounding).

Spectra (each of shape (n_damping, n_periods); units in ``ResponseSpectrum.units``)
    SD  = max |u|               [m]      SV  = max |u'|            [m/s]
    SA  = max |u'' + a_g|       [m/s^2]  (absolute acceleration = -2 zeta omega u' - omega^2 u)
    PSV = omega SD              [m/s]    PSA = omega^2 SD          [m/s^2]
    Peaks (issue 43): by default each is found WITHIN its step, as the extremum of the
    closed form of the exactly integrated oscillator (``_exact_peaks``, ``_exact_rotd``),
    so no sub-steps are needed; round-off remains (1e-12 against closed forms and dense
    sampling in tests/seismic/test_exact_peaks.py).  With peaks="nodes" they are taken
    over the samples (and the ``oversample`` sub-steps) only, and a peak between samples
    is missed by up to 1 - cos(omega dt / 2) ~ (omega dt)^2 / 8 relative (more for SA and
    SV where the ground's own content is faster), so there ask for
    ``oversample = ceil(10 dt / T)`` sub-steps (a_g stays linear inside a step, so the
    sub-step response is exact too).  T = 0 is the rigid limit: SA = PSA = PGA (peak
    |a_g| at the samples), SD = SV = PSV = 0.

Recurrence (Nigam & Jennings 1969, written with phi-functions)
    With y = (omega u, u') the oscillator reads y' = omega K y - e2 a_g(t),
    K = [[0, 1], [-1, -2 zeta]].  Over a step [t_i, t_i + h] on which a_g is linear,
    variation of constants with sigma = (t_i + h - s) / h and M = omega h K gives
        y_{i+1} = e^M y_i - h int_0^1 e^{M sigma} e2 (a_i sigma + a_{i+1} (1 - sigma)) dsigma
                = A y_i + B (a_i, a_{i+1})^T,
        A = e^M,  B = -h [ (phi1(M) - phi2(M)) e2 ,  phi2(M) e2 ],
        phi1(z) = (e^z - 1) / z = int_0^1 e^{z sigma} dsigma,
        phi2(z) = (e^z - 1 - z) / z^2 = int_0^1 e^{z sigma} (1 - sigma) dsigma.
    M has the eigenvalues lambda, conj(lambda) = omega h (-zeta +- i s), s = sqrt(1 - zeta^2)
    (0 <= zeta < 1).  For a real 2x2 matrix with eigenvalues alpha +- i beta every analytic
    f obeys f(M) = Re f(lambda) I + Im f(lambda) / beta (M - alpha I) (Cayley-Hamilton);
    here M - alpha I = omega h [[zeta, 1], [-1, -zeta]] and beta = omega h s, so
        A = Re e^lambda I + (Im e^lambda / s) [[zeta, 1], [-1, -zeta]],
        f(M) e2 = (Im f(lambda) / s,  Re f(lambda) - zeta Im f(lambda) / s)^T.
    Expanded (Re e^lambda = e^{-zeta omega h} cos(omega_d h), ...) these are Nigam and
    Jennings' coefficients; the phi form needs no case for omega h << 1, where their
    explicit expressions cancel catastrophically: phi1, phi2 are summed as series for
    |lambda| < 0.5.  The time loop is numpy over all (T, zeta) pairs at once; A and B are
    computed once per distinct step length (relative 1e-12), so uniform grids cost one.

Two horizontal components (Boore 2010)
    The response to the component rotated by theta, a_x cos(theta) + a_y sin(theta), is
    u_x cos(theta) + u_y sin(theta): both displacement histories are integrated once and
    combined for n_angles angles theta_j = j 180 deg / n_angles.  RotDnn is the nn-th
    percentile (numpy's linear interpolation) over the angles of the peak |u_theta|,
    reported as PSA = omega^2 x that (SD, PSV alongside).  RotD00/RotD100 are the
    minimum/maximum over the angle grid (continuous angles: RotD100 larger by at most
    1 / cos(90 deg / n_angles) - 1).
"""
import csv
import math
from collections import namedtuple
from dataclasses import dataclass, field

import numpy as np

QUANTITIES = ("SA", "PSA", "PSV", "SD", "SV")
UNITS = {"period": "s", "damping": "-", "SA": "m/s^2", "PSA": "m/s^2", "PSV": "m/s",
         "SD": "m", "SV": "m/s"}
# NGA-West2 ground-motion model periods (Bozorgnia et al. 2014, Earthquake Spectra 30(3)), s
NGA_PERIODS = (0.01, 0.02, 0.03, 0.05, 0.075, 0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5, 0.75,
               1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 7.5, 10.0)
_SERIES_RADIUS = 0.5          # |lambda| below which phi1, phi2 are summed as series
_SERIES_TERMS = 18            # terms up to z^18: remainder < 0.5^19 / 20! < 1e-23
_BLOCK_VALUES = 2_000_000     # float64 values per history block buffer (16 MB)


class SpectrumInputError(ValueError):
    """Invalid input for a response spectrum (one-line message)."""


@dataclass(frozen=True, eq=False)
class ResponseSpectrum:
    """Spectral values ``values[name]`` of shape (n_damping, n_periods) for the names in
    QUANTITIES that were asked for, with their units in ``units``."""
    periods: np.ndarray
    damping: np.ndarray
    values: dict
    units: dict = field(default_factory=lambda: dict(UNITS))
    label: str = ""

    def __getitem__(self, name):
        return self.values[name]

    @property
    def quantities(self):
        return tuple(q for q in QUANTITIES if q in self.values)


OscillatorHistory = namedtuple("OscillatorHistory", "t u v a_abs")
OscillatorHistory.__doc__ = ("Node times t [s], relative displacement u [m], relative velocity "
                             "v [m/s], absolute acceleration a_abs [m/s^2].")


# ----------------------------------------------------------------------------- input checks
def _check_series(t, *series):
    """t (n,) and each series (n,) as float arrays; SpectrumInputError otherwise."""
    t = np.asarray(t, dtype=float)
    out = [np.asarray(a, dtype=float) for a in series]
    if t.ndim != 1 or any(a.ndim != 1 for a in out):
        raise SpectrumInputError("time and acceleration series must be one-dimensional")
    if t.size == 0 or any(a.size == 0 for a in out):
        raise SpectrumInputError("the series is empty")
    if any(a.size != t.size for a in out):
        sizes = ", ".join(str(a.size) for a in out)
        raise SpectrumInputError(f"mismatched lengths: {t.size} times, {sizes} accelerations")
    if t.size < 2:
        raise SpectrumInputError("a response spectrum needs at least 2 samples")
    if not np.all(np.isfinite(t)) or not all(np.all(np.isfinite(a)) for a in out):
        raise SpectrumInputError("the series holds non-finite values (nan or inf)")
    steps = np.diff(t)
    if not np.all(steps > 0):
        k = int(np.argmin(steps))
        raise SpectrumInputError(f"times are not strictly increasing: t[{k + 1}] = "
                                 f"{float(t[k + 1])!r} after t[{k}] = {float(t[k])!r}")
    return (t, *out)


def _check_grid(periods, damping):
    """periods (n,) >= 0 and damping (m,) in [0, 1), both finite and non-empty."""
    periods = np.atleast_1d(np.asarray(standard_periods() if periods is None else periods,
                                       dtype=float))
    damping = np.atleast_1d(np.asarray(damping, dtype=float))
    for name, x in (("periods", periods), ("damping", damping)):
        if x.ndim != 1 or x.size == 0:
            raise SpectrumInputError(f"{name} must be a non-empty one-dimensional list")
        if not np.all(np.isfinite(x)):
            raise SpectrumInputError(f"{name} hold non-finite values")
    if np.any(periods < 0):
        raise SpectrumInputError(f"periods must be >= 0, got {periods.min():g} s")
    if np.any((damping < 0) | (damping >= 1)):
        bad = damping[(damping < 0) | (damping >= 1)][0]
        raise SpectrumInputError(f"damping ratios must lie in [0, 1), got {bad:g}")
    return periods, damping


def _check_int(name, value, minimum=1):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise SpectrumInputError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _check_quantity(quantity):
    names = QUANTITIES if quantity == "all" else (quantity,) if isinstance(quantity, str) \
        else tuple(quantity)
    bad = [q for q in names if q not in QUANTITIES]
    if bad or not names:
        raise SpectrumInputError(f"unknown quantity {bad[0] if bad else '()'!r}; "
                                 f"choose from {', '.join(QUANTITIES)} or 'all'")
    return names


# ----------------------------------------------------------------------------- recurrence
def _phi12(z):
    """phi1(z) = (e^z - 1) / z and phi2(z) = (e^z - 1 - z) / z^2 for complex z, with the
    Taylor series sum_j z^j / (j + k)! where |z| < _SERIES_RADIUS (no cancellation)."""
    z = np.asarray(z, dtype=complex)
    small = np.abs(z) < _SERIES_RADIUS
    zs = np.where(small, z, 0.0)
    zb = np.where(small, 1.0, z)
    ez = np.exp(zb)
    p1 = np.where(small, 0.0, (ez - 1.0) / zb)
    p2 = np.where(small, 0.0, (ez - 1.0 - zb) / zb ** 2)
    s1 = np.full_like(zs, 1.0 / math.factorial(_SERIES_TERMS + 1))
    s2 = np.full_like(zs, 1.0 / math.factorial(_SERIES_TERMS + 2))
    for j in range(_SERIES_TERMS - 1, -1, -1):
        s1 = s1 * zs + 1.0 / math.factorial(j + 1)
        s2 = s2 * zs + 1.0 / math.factorial(j + 2)
    return np.where(small, s1, p1), np.where(small, s2, p2)


def _step_matrices(h, omega, zeta):
    """A (2, 2, P) and B (2, 2, P) of y_{i+1} = A y_i + B (a_i, a_{i+1}) for y = (omega u, u'),
    step h [s], omega (P,) [rad/s] > 0, zeta (P,) in [0, 1) (module docstring)."""
    s = np.sqrt(1.0 - zeta ** 2)
    lam = omega * h * (-zeta + 1j * s)
    e = np.exp(lam)
    ce, se = e.real, e.imag / s
    A = np.array([[ce + zeta * se, se], [-se, ce - zeta * se]])
    phi1, phi2 = _phi12(lam)

    def col(f):             # f(M) e2
        im = f.imag / s
        return np.array([im, f.real - zeta * im])

    B = -h * np.stack([col(phi1 - phi2), col(phi2)], axis=1)
    return A, B


def _march(t, acc, omega, zeta, oversample=1):
    """Yield blocks (y0, y1), each (rows, c, P), of y = (omega u, u') at every node after t[0]
    (samples and sub-steps) for the c ground accelerations acc (c, n).  The buffers are
    reused: consume a block before asking for the next."""
    c, P, k = acc.shape[0], omega.size, oversample
    if c * P == 0:                  # only T = 0 asked (the rigid limit, the PGA): no oscillator to march
        return
    rows = max(1, _BLOCK_VALUES // (c * P))
    buf0, buf1 = np.empty((rows, c, P)), np.empty((rows, c, P))
    y0, y1 = np.zeros((c, P)), np.zeros((c, P))
    cache, r = {}, 0
    for i in range(t.size - 1):
        h = (t[i + 1] - t[i]) / k
        key = f"{h:.12e}"
        if key not in cache:
            if len(cache) > 256:
                cache.clear()
            cache[key] = _step_matrices(h, omega, zeta)
        (a00, a01), (a10, a11) = cache[key][0]
        (b00, b01), (b10, b11) = cache[key][1]
        for j in range(k):
            g0 = (acc[:, i] * (1 - j / k) + acc[:, i + 1] * (j / k))[:, None]
            g1 = (acc[:, i] * (1 - (j + 1) / k) + acc[:, i + 1] * ((j + 1) / k))[:, None]
            buf0[r] = a00 * y0 + a01 * y1 + b00 * g0 + b01 * g1
            buf1[r] = a10 * y0 + a11 * y1 + b10 * g0 + b11 * g1
            y0, y1 = buf0[r], buf1[r]
            r += 1
            if r == rows:
                y0, y1 = y0.copy(), y1.copy()
                yield buf0, buf1
                r = 0
    if r:
        yield buf0[:r], buf1[:r]


QUARTER = 0.5 * np.pi      # exact peaks: each step is searched in pieces of at most a quarter period


def _exact_peaks(t, acc, omega, zeta, oversample=1):
    """(max |omega u|, max |u'|, max |omega u + 2 zeta u'|) (P,) over the whole record, each peak found
    WITHIN its step from the closed form of the exactly integrated oscillator (a_g linear in the step):
    y(s) = A(s) y_i + B(s) (a_i, a(s)), ``_step_matrices`` at the length s.

    Which steps: the energy radius |y| = sqrt((omega u)^2 + u'^2) obeys d|y|/dt = (-2 zeta omega u'^2 -
    u' a_g)/|y|, between -|a_g| - 2 zeta omega |y| and |a_g|, so inside a step of length h no quantity
    exceeds R = min(|y_i| + h g, (|y_i+1| + h g) e^(2 zeta omega h)), g = max(|a_i|, |a_i+1|) (times
    sqrt(1 + 4 zeta^2) for omega u + 2 zeta u'): only steps whose R beats the running peak (the largest
    value at the samples so far) are searched, a rigorous bound; and within a piece an extremum rises
    above the nearer end by at most max|q''| (piece/2)^2 / 2, |q''| bounded from the same R. How: the step is cut into m = ceil(omega h / (pi / 2))
    pieces; where the quantity's derivative q' (from the closed form) changes sign in a piece, its
    zero is found by bisection (30 halvings: s* to 1e-9 of the piece, q to round-off since the error
    in q is quadratic in that of s*), and |q(s*)| enters the peak. What remains: an extremum pair
    inside one piece (q' touching zero twice within a quarter period, a shallow bump of the forced
    response), which sampling misses as well."""
    P = omega.size
    best = np.zeros((3, P))
    prev0, prev1 = np.zeros(P), np.zeros(P)
    n0, k = 0, oversample
    for y0, y1 in _march(t, acc[None, :], omega, zeta, k):
        rows = y0.shape[0]
        e0, e1 = y0[:, 0], y1[:, 0]                   # (rows, P): the ends of the block's steps
        s0 = np.concatenate([prev0[None], e0[:-1]])   # their starts
        s1 = np.concatenate([prev1[None], e1[:-1]])
        prev0, prev1 = e0[-1].copy(), e1[-1].copy()
        nn = n0 + np.arange(rows)                     # node nn ends sub-step j of sample step i
        i, j = nn // k, nn % k
        n0 += rows
        h = (t[i + 1] - t[i]) / k
        g0 = acc[i] + (acc[i + 1] - acc[i]) * (j / k)
        g1 = acc[i] + (acc[i + 1] - acc[i]) * ((j + 1) / k)
        hg = (h * np.maximum(np.abs(g0), np.abs(g1)))[:, None]
        env = np.minimum(np.hypot(s0, s1) + hg, (np.hypot(e0, e1) + hg) * np.exp(2 * zeta * omega * h[:, None]))
        one = (omega[None, :] * h[:, None] <= QUARTER * (1 + 1e-9))    # one piece: q' must change sign at the ends
        ends = (e0, e1, e0 + 2 * zeta * e1)
        for q in range(3):
            np.maximum(best[q], np.abs(ends[q]).max(axis=0), out=best[q])
            fac = np.sqrt(1 + 4 * zeta ** 2) if q == 2 else 1.0
            turn = _slope(q, s0, s1, g0[:, None], omega, zeta) * _slope(q, e0, e1, g1[:, None], omega, zeta) < 0
            r, p = np.nonzero((env * fac > best[q][None, :]) & (turn | ~one))
            if r.size:
                val, at = _search(q, s0[r, p], s1[r, p], g0[r], g1[r], h[r], omega[p], zeta[p], best[q][p] / (fac[p] if q == 2 else 1.0))
                np.maximum.at(best[q], p[at], val)
    return best[0], best[1], best[2]


def _state(s, y0, y1, g0, g1, h, omega, zeta):
    """y = (omega u, u') at s (N,) into the steps starting at (y0, y1) with the ground g0 -> g1 over h,
    and the ground a_g(s)."""
    A, B = _step_matrices(s, omega, zeta)
    gs = g0 + (g1 - g0) * (s / h)
    return (A[0, 0] * y0 + A[0, 1] * y1 + B[0, 0] * g0 + B[0, 1] * gs,
            A[1, 0] * y0 + A[1, 1] * y1 + B[1, 0] * g0 + B[1, 1] * gs, gs)


def _slope(q, a, b, g, omega, zeta):
    """q' for q = omega u (0), u' (1), omega u + 2 zeta u' (2) from y = (a, b) and the ground g."""
    ar = -g - 2 * zeta * omega * b - omega * a                  # u''
    return (omega * b, ar, omega * b + 2 * zeta * ar)[q]


def _pieces(h, omega):
    """The points 0 = s_0 < ... < s_m = h (N, M + 1) of m = ceil(omega h / (pi / 2)) pieces per step (the
    last point repeated up to the largest M)."""
    m = np.maximum(1, np.ceil(omega * h / QUARTER - 1e-9)).astype(int)
    M = int(m.max())
    jj = np.minimum(np.arange(M + 1)[None, :], m[:, None])
    return h[:, None] * jj / m[:, None]


MAX_PIECES = 10 ** 8         # quarter-period pieces of all steps beyond which exact peaks are refused


def _check_pieces(t, omega, oversample):
    """SpectrumInputError when the exact peaks' quarter-period pieces over the whole record exceed
    ``MAX_PIECES`` (a period far below the sampling step: 4 dt / T pieces a step; a period of 1e-7 s
    under a 5 ms record took the machine's memory)."""
    if omega.size == 0 or t.size < 2:
        return
    h = float(np.max(np.diff(t))) / oversample
    pieces = int(np.ceil(float(omega.max()) * h / QUARTER - 1e-9))
    total = pieces * (t.size - 1) * oversample
    if total > MAX_PIECES:
        raise SpectrumInputError(f"exact peaks of the period {2 * np.pi / float(omega.max()):.3g} s need {pieces} "
                                 f"pieces in each of {(t.size - 1) * oversample} steps ({total:.3g} in all, more than "
                                 f"{MAX_PIECES:.0e}); give longer periods or peaks='nodes'")


def _at_pieces(y0, y1, g0, g1, h, omega, zeta):
    """(S, a, b, g) (N, M + 1): the states y = (a, b) and the ground g at the pieces' points S of each
    candidate step; the step matrices are formed once per distinct (h, omega, zeta) (a uniform record
    has one h: one set per oscillator)."""
    key = np.stack([h, omega, zeta], axis=1)
    uk, inv = np.unique(key, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    Su = _pieces(uk[:, 0], uk[:, 1])                          # (U, M + 1)
    U, M1 = Su.shape
    A, B = _step_matrices(Su.ravel(), np.repeat(uk[:, 1], M1), np.repeat(uk[:, 2], M1))
    A, B = A.reshape(2, 2, U, M1)[:, :, inv], B.reshape(2, 2, U, M1)[:, :, inv]
    S = Su[inv]
    gs = g0[:, None] + (g1 - g0)[:, None] * (S / h[:, None])
    y0, y1, g0 = y0[:, None], y1[:, None], g0[:, None]
    return (S, A[0, 0] * y0 + A[0, 1] * y1 + B[0, 0] * g0 + B[0, 1] * gs,
            A[1, 0] * y0 + A[1, 1] * y1 + B[1, 0] * g0 + B[1, 1] * gs, gs)


TAYLOR_TERMS = 26          # degree of the piece polynomials: (pi/2)^26 / 26! < 1e-21 of the amplitude


def _taylor(a, b, g, gd, omega, zeta, ds, n=TAYLOR_TERMS):
    """(N, n + 1) coefficients D_k of u(s) = sum D_k x^k, x = s / ds in [0, 1], from the state y = (a, b) =
    (omega u, u') and the ground g (slope gd) at the piece's start: the ODE's derivatives
    u^(k+2) = -g^(k) - 2 zeta omega u^(k+1) - omega^2 u^(k) (g^(k) = 0 for k >= 2) scaled by ds^k / k!:
    D_{k+2} = -g^(k) ds^(k+2)/(k+2)! - 2 zeta omega ds D_{k+1}/(k+2) - (omega ds)^2 D_k/((k+2)(k+1)).
    The series of the exact solution (an entire function); with omega ds <= pi/2 its terms fall as
    (pi/2)^k / k!, so the polynomial is the closed form to round-off."""
    D = np.zeros((a.size, n + 1))
    D[:, 0], D[:, 1] = a / omega, b * ds
    wd = omega * ds
    for k in range(n - 1):
        gk = g if k == 0 else gd if k == 1 else 0.0
        force = -gk * ds ** (k + 2) / math.factorial(k + 2) if k < 2 else 0.0
        D[:, k + 2] = force - 2 * zeta * wd * D[:, k + 1] / (k + 2) - wd * wd * D[:, k] / ((k + 2) * (k + 1))
    return D


def _horner(C, x):
    """sum_k C[:, k] x^k and its derivative (C (K, n + 1), x (K,))."""
    p, dp = C[:, -1].copy(), np.zeros_like(x)
    for k in range(C.shape[1] - 2, -1, -1):
        dp = dp * x + p
        p = p * x + C[:, k]
    return p, dp


def _quantity_poly(q, D, omega, zeta, ds):
    """Coefficients (in x) of q = omega u (0), u' (1), omega u + 2 zeta u' (2) from those of u."""
    k = np.arange(1, D.shape[1])
    du = np.zeros_like(D)
    du[:, :-1] = D[:, 1:] * k / ds[:, None]                     # u' = (1/ds) du/dx
    w, z = omega[:, None], zeta[:, None]
    return (w * D, du, w * D + 2 * z * du)[q]


def _poly_peak(C, lo, hi):
    """|q(x*)| at the zero x* of q' in [lo, hi] (q' of opposite signs there), q the polynomial C:
    safeguarded Newton on q' (bisection where the Newton point leaves the bracket or the bracket did
    not halve), to 1e-14 of the piece."""
    k = np.arange(1, C.shape[1])
    C1 = np.zeros_like(C)
    C1[:, :-1] = C[:, 1:] * k
    f_lo = _horner(C1, lo)[0]
    f_hi = _horner(C1, hi)[0]
    x = lo + (hi - lo) * f_lo / (f_lo - f_hi)
    act = np.arange(x.size)
    lo, hi = lo.copy(), hi.copy()
    for _ in range(200):
        if not act.size:
            break
        f, fp = _horner(C1[act], x[act])
        width = hi[act] - lo[act]
        same = f * f_lo[act] > 0
        lo[act] = np.where(same, x[act], lo[act])
        hi[act] = np.where(same, hi[act], x[act])
        with np.errstate(divide="ignore", invalid="ignore"):
            nxt = x[act] - f / fp
        ok = np.isfinite(nxt) & (nxt > lo[act]) & (nxt < hi[act]) & (hi[act] - lo[act] <= 0.5 * width)
        new = np.where(ok, nxt, 0.5 * (lo[act] + hi[act]))
        moving = (np.abs(new - x[act]) > 1e-14) & (hi[act] - lo[act] > 1e-14)
        x[act] = new
        act = act[moving]
    return np.abs(_horner(C, x)[0])


def _search(q, y0, y1, g0, g1, h, omega, zeta, beat):
    """(|q| at every interior extremum of the candidate steps, the candidate index of each); ``beat``:
    the energy radius a piece must be able to reach to matter (the running peak, over the factor
    of q = omega u + 2 zeta u')."""
    S, a, b, g = _at_pieces(y0, y1, g0, g1, h, omega, zeta)   # (N, M + 1)
    d = _slope(q, a, b, g, omega[:, None], zeta[:, None])
    rad = np.hypot(a, b)
    hg = np.diff(S, axis=1) * np.maximum(np.abs(g[:, :-1]), np.abs(g[:, 1:]))
    env = np.minimum(rad[:, :-1] + hg, (rad[:, 1:] + hg) * np.exp(2 * zeta[:, None] * omega[:, None] * np.diff(S, axis=1)))
    # the extremum rises above the piece's nearer end by at most max|q''| (ds/2)^2 / 2; bounds of |q''| from
    # |u''| <= |a_g| + omega (1 + 2 zeta) E, E <= the energy radius's bound over the piece
    w, z = omega[:, None], zeta[:, None]
    ds = np.diff(S, axis=1)
    gm = np.maximum(np.abs(g[:, :-1]), np.abs(g[:, 1:]))
    E = np.maximum(rad[:, :-1], rad[:, 1:]) + ds * gm
    arel = gm + w * (1 + 2 * z) * E
    c1 = np.abs((g1 - g0) / h)[:, None] + 2 * z * w * arel + w * w * E
    curv = (w * arel, c1, w * arel + 2 * z * c1)[q]
    qv = np.abs((a, b, a + 2 * z * b)[q])
    reach = np.maximum(qv[:, :-1], qv[:, 1:]) + 0.5 * curv * (0.5 * ds) ** 2
    fac = np.sqrt(1 + 4 * zeta ** 2)[:, None] if q == 2 else 1.0
    n, jx = np.nonzero((d[:, :-1] * d[:, 1:] < 0) & (env > beat[:, None]) & (reach > beat[:, None] * fac))
    if not n.size:
        return np.zeros(0), np.zeros(0, int)
    ds = S[n, jx + 1] - S[n, jx]                                # the piece, from its start's state
    D = _taylor(a[n, jx], b[n, jx], g[n, jx], (g1[n] - g0[n]) / h[n], omega[n], zeta[n], ds)
    C = _quantity_poly(q, D, omega[n], zeta[n], ds)
    return _poly_peak(C, np.zeros(n.size), np.ones(n.size)), n


def _pairs(periods, damping):
    """omega, zeta (P,) of the (damping, period) pairs with T > 0, row-major over
    (n_damping, n_periods), and the mask of T > 0."""
    pos = periods > 0
    omega = np.zeros(periods.shape)
    omega[pos] = 2 * np.pi / periods[pos]
    om, ze = np.meshgrid(omega[pos], damping)
    return om.ravel(), ze.ravel(), pos


# ----------------------------------------------------------------------------- single component
def sdof_history(t, acc, period, damping=0.05, oversample=1):
    """Response of one oscillator (scalar period [s], damping [-]) to a_g = acc [m/s^2] at
    the samples and the ``oversample`` sub-steps: OscillatorHistory(t, u, v, a_abs)."""
    t, acc = _check_series(t, acc)
    periods, damping = _check_grid([period], [damping])
    k = _check_int("oversample", oversample)
    nodes = np.concatenate([t[:1], (t[:-1, None] + np.diff(t)[:, None]
                                    * (np.arange(1, k + 1) / k)).ravel()])
    nodes[::k] = t                  # the samples themselves, not t[i] + (t[i+1] - t[i])
    if periods[0] == 0:
        zero = np.zeros(nodes.size)
        return OscillatorHistory(nodes, zero, zero, np.interp(nodes, t, acc))
    omega, zeta, _ = _pairs(periods, damping)
    blocks = [(b0[:, 0, 0].copy(), b1[:, 0, 0].copy())
              for b0, b1 in _march(t, acc[None, :], omega, zeta, k)]
    y0 = np.concatenate([[0.0]] + [b[0] for b in blocks])
    y1 = np.concatenate([[0.0]] + [b[1] for b in blocks])
    return OscillatorHistory(nodes, y0 / omega[0], y1, -omega[0] * (y0 + 2 * zeta[0] * y1))


def sdof_filter(frequency, damping, dt):
    """(b, a): the recurrence above for the ABSOLUTE acceleration of one oscillator (natural
    frequency [Hz] > 0, damping [-] in [0, 1)) on a uniform step dt [s], as the coefficients of
    a second-order digital filter a_abs = lfilter(b, a, a_g) (numpy arrays of 3).  Exact for
    the piecewise-linear a_g through the samples and the oscillator at rest at the first sample
    when a_g[0] = 0 (lfilter takes the samples before the first as 0, i.e. a ramp from 0 over
    the step before it otherwise).

    With y = (omega u, u'), y_{i+1} = A y_i + b0 a_i + b1 a_{i+1} and a_abs = C y,
    C = -omega (1, 2 zeta): a_abs = C (q I - A)^-1 (b0 + q b1) a_g, q the forward shift, so
    b = (C b1, C b0 + C J b1, C J b0), J = adj(q I - A) - q I = [[-A11, A01], [A10, -A00]],
    a = (1, -tr A, det A)."""
    f, z, h = float(frequency), float(damping), float(dt)
    if not (np.isfinite(f) and f > 0 and np.isfinite(h) and h > 0 and 0 <= z < 1):
        raise SpectrumInputError(f"sdof_filter: needs frequency > 0 Hz, dt > 0 s and damping in [0, 1) "
                                 f"(got {frequency!r}, {dt!r}, {damping!r})")
    omega = 2 * np.pi * f
    A, B = _step_matrices(h, np.array([omega]), np.array([z]))
    A, b0, b1 = A[:, :, 0], B[:, 0, 0], B[:, 1, 0]
    C = -omega * np.array([1.0, 2 * z])
    J = np.array([[-A[1, 1], A[0, 1]], [A[1, 0], -A[0, 0]]])
    b = np.array([C @ b1, C @ b0 + C @ J @ b1, C @ J @ b0])
    a = np.array([1.0, -np.trace(A), np.linalg.det(A)])
    return b, a


def response_spectrum(t, acc, periods=None, damping=(0.05,), quantity="all", oversample=1, peaks="exact"):
    """Response spectra of the ground acceleration ``acc`` [m/s^2] sampled at ``t`` [s].

    periods [s] (default ``standard_periods()``; 0 allowed: rigid limit), damping ratios
    in [0, 1), quantity "all" or names from QUANTITIES, oversample sub-steps per sample
    step.  peaks: "exact" (default: each peak found within its step from the closed form,
    ``_exact_peaks``) or "nodes" (the largest value at the samples and sub-steps, the
    module docstring's bound).  Returns a ResponseSpectrum with arrays (n_damping, n_periods)."""
    t, acc = _check_series(t, acc)
    periods, damping = _check_grid(periods, damping)
    names = _check_quantity(quantity)
    k = _check_int("oversample", oversample)
    if peaks not in ("exact", "nodes"):
        raise SpectrumInputError(f"peaks must be 'exact' or 'nodes', got {peaks!r}")
    omega, zeta, pos = _pairs(periods, damping)
    pd, pv, pa = np.zeros(omega.size), np.zeros(omega.size), np.zeros(omega.size)
    if peaks == "exact":
        _check_pieces(t, omega, k)
        pd, pv, pa = _exact_peaks(t, acc, omega, zeta, k)
    else:
        for y0, y1 in _march(t, acc[None, :], omega, zeta, k):
            np.maximum(pd, np.abs(y0[:, 0]).max(axis=0), out=pd)
            np.maximum(pv, np.abs(y1[:, 0]).max(axis=0), out=pv)
            np.maximum(pa, np.abs(y0[:, 0] + 2 * zeta * y1[:, 0]).max(axis=0), out=pa)
    shape = (damping.size, int(pos.sum()))
    om = omega.reshape(shape)
    pos_vals = {"SD": pd.reshape(shape) / om, "SV": pv.reshape(shape),
                "SA": om * pa.reshape(shape), "PSV": pd.reshape(shape),
                "PSA": om * pd.reshape(shape)}
    pga = np.abs(acc).max()
    values = {}
    for q in names:
        full = np.full((damping.size, periods.size), pga if q in ("SA", "PSA") else 0.0)
        full[:, pos] = pos_vals[q]
        values[q] = full
    return ResponseSpectrum(periods, damping, values)


def standard_periods(n_log=100, t_min=0.01, t_max=10.0, nga=True, pga=False):
    """Sorted periods [s]: ``n_log`` log-spaced from t_min to t_max, merged with the 21
    NGA-West2 periods 0.01 ... 10 s (NGA_PERIODS) when ``nga``, and T = 0 (PGA) first when
    ``pga``; values equal to 12 significant digits are merged."""
    if not (0 < t_min < t_max and np.isfinite(t_max)):
        raise SpectrumInputError(f"need 0 < t_min < t_max, got {t_min!r}, {t_max!r}")
    n = _check_int("n_log", n_log, minimum=0)
    p = np.geomspace(t_min, t_max, n) if n > 1 else np.array([t_min] * n)
    if nga:
        p = np.concatenate([p, NGA_PERIODS])
    p = np.unique([float(f"{x:.12g}") for x in p])
    return np.concatenate([[0.0], p]) if pga else p


# ----------------------------------------------------------------------------- two components
def rotd(t, ax, ay, periods=None, damping=(0.05,), percentiles=(50, 100), n_angles=180,
         oversample=1, peaks="exact"):
    """Orientation-independent spectra RotDnn (Boore 2010) of the horizontal pair ax, ay
    [m/s^2]: {percentile: ResponseSpectrum with PSA, PSV, SD}.  T = 0 gives the percentile of
    the peak rotated ground acceleration.  See the module docstring."""
    t, ax, ay = _check_series(t, ax, ay)
    periods, damping = _check_grid(periods, damping)
    n = _check_int("n_angles", n_angles)
    q = np.atleast_1d(np.asarray(percentiles, dtype=float))
    if q.ndim != 1 or q.size == 0 or not np.all((q >= 0) & (q <= 100)):
        raise SpectrumInputError(f"percentiles must lie in [0, 100], got {percentiles!r}")
    theta = np.arange(n) * np.pi / n
    cs = np.stack([np.cos(theta), np.sin(theta)])                # (2, n)
    omega, zeta, pos = _pairs(periods, damping)
    k = _check_int("oversample", oversample)
    if peaks not in ("exact", "nodes"):
        raise SpectrumInputError(f"peaks must be 'exact' or 'nodes', got {peaks!r}")
    if peaks == "exact":                                          # each angle's peak within its step
        _check_pieces(t, omega, k)
        peak = _exact_rotd(t, np.stack([ax, ay]), omega, zeta, cs, k)
    else:
        peak = np.zeros((omega.size, n))                          # peak |omega^2 u_theta| at the nodes
        for y0, _ in _march(t, np.stack([ax, ay]), omega, zeta, k):
            np.maximum(peak, _rotated_peaks(omega * y0, cs), out=peak)
    shape = (damping.size, int(pos.sum()))
    om = omega.reshape(shape)
    ground = np.abs(np.stack([ax, ay], axis=1) @ cs).max(axis=0)  # (n,) rotated PGA
    out = {}
    for pct in q:
        psa = np.empty((damping.size, periods.size))
        psa[:, ~pos] = np.percentile(ground, pct)
        psa[:, pos] = np.percentile(peak, pct, axis=1).reshape(shape)
        sd, psv = np.zeros_like(psa), np.zeros_like(psa)
        sd[:, pos], psv[:, pos] = psa[:, pos] / om ** 2, psa[:, pos] / om
        key = int(pct) if float(pct).is_integer() else float(pct)
        out[key] = ResponseSpectrum(periods, damping, {"PSA": psa, "PSV": psv, "SD": sd},
                                    label=f"RotD{key:02}" if isinstance(key, int) else f"RotD{key}")
    return out


def _exact_rotd(t, acc2, omega, zeta, cs, oversample=1):
    """(P, n_angles): max over the record of |omega^2 u_theta| for the angles of ``cs`` (2, n), each peak
    found within its step as in ``_exact_peaks``: the pair's energy radius E = |(y_x, y_y)| bounds every
    angle's |omega u_theta| and changes at most by |(a_x, a_y)| per unit time, so a step is searched when
    min(E_i, E_i+1) + h max |a_g| beats the smallest angle's running peak; then for each angle whose
    peak it can beat, the zeros of the projected velocity in the step's quarter-period pieces are found
    by bisection on the two components' closed forms."""
    P, n_ang = omega.size, cs.shape[1]
    if not np.allclose(cs, [np.cos(np.arange(n_ang) * np.pi / n_ang), np.sin(np.arange(n_ang) * np.pi / n_ang)],
                       rtol=0, atol=1e-14):
        raise SpectrumInputError("_exact_rotd needs the angles j pi / n (rotd's grid)")
    peak = np.zeros((P, n_ang))                                # |omega y0_theta| = |omega^2 u_theta|
    prev0, prev1 = np.zeros((2, P)), np.zeros((2, P))
    n0, k = 0, oversample
    for y0, y1 in _march(t, acc2, omega, zeta, k):
        rows = y0.shape[0]
        np.maximum(peak, _rotated_peaks(omega * y0, cs), out=peak)
        s0 = np.concatenate([prev0[None], y0[:-1]])
        s1 = np.concatenate([prev1[None], y1[:-1]])
        prev0, prev1 = y0[-1].copy(), y1[-1].copy()
        nn = n0 + np.arange(rows)
        i, j = nn // k, nn % k
        n0 += rows
        h = (t[i + 1] - t[i]) / k
        g0 = (acc2[:, i] + (acc2[:, i + 1] - acc2[:, i]) * (j / k)).T            # (rows, 2)
        g1 = (acc2[:, i] + (acc2[:, i + 1] - acc2[:, i]) * ((j + 1) / k)).T
        E = lambda a, b: np.sqrt((a ** 2 + b ** 2).sum(axis=1))                  # noqa: E731  (rows, P)
        gm = np.maximum(np.hypot(g0[:, 0], g0[:, 1]), np.hypot(g1[:, 0], g1[:, 1]))
        hg = (h * gm)[:, None]
        env = np.minimum(E(s0, s1) + hg, (E(y0, y1) + hg) * np.exp(2 * zeta * omega * h[:, None]))
        # a step of one piece turns only where some angle's projected velocity changes sign: the end
        # velocities (x, y) at both ends, v_s . e_theta and v_e . e_theta of opposite signs for some theta,
        # i.e. unless the two vectors lie strictly on one side of a line through 0 (angle between < 90 deg
        # and ... ): test with the angle grid itself below; here only the bound
        one = (omega[None, :] * h[:, None] <= QUARTER * (1 + 1e-9))
        turn = ((s1[:, 0] * y1[:, 0] + s1[:, 1] * y1[:, 1]) < np.hypot(s1[:, 0], s1[:, 1]) * np.hypot(y1[:, 0], y1[:, 1]))
        r, p = np.nonzero((env * omega[None, :] > peak.min(axis=1)[None, :]) & (turn | ~one))
        if not r.size:
            continue
        st = [_at_pieces(s0[r, c, p], s1[r, c, p], g0[r, c], g1[r, c], h[r], omega[p], zeta[p]) for c in (0, 1)]
        S = st[0][0]                                                             # (N, M + 1)
        E2 = np.sqrt(st[0][1] ** 2 + st[0][2] ** 2 + st[1][1] ** 2 + st[1][2] ** 2)     # (N, M + 1)
        gp = np.maximum(np.hypot(st[0][3], st[1][3])[:, :-1], np.hypot(st[0][3], st[1][3])[:, 1:])
        hg = np.diff(S, axis=1) * gp
        penv = np.minimum(E2[:, :-1] + hg, (E2[:, 1:] + hg) * np.exp(2 * zeta[p][:, None] * omega[p][:, None] *
                                                                     np.diff(S, axis=1))) * omega[p][:, None]   # (N, M)
        # each angle: the extremum rises above the piece's nearer end by at most max|q''| (ds/2)^2 / 2,
        # q = omega^2 u_theta, |q''| <= omega^2 (|a_g| + omega (1 + 2 zeta) E) (E: the energy radius's bound)
        w_ = omega[p][:, None]
        ds_ = np.diff(S, axis=1)
        Emax = np.maximum(E2[:, :-1], E2[:, 1:]) + ds_ * gp
        rise = 0.5 * w_ ** 2 * (gp + w_ * (1 + 2 * zeta[p][:, None]) * Emax) * (0.5 * ds_) ** 2       # (N, M)
        # the angles whose projected velocity changes sign in a piece: (V_s . e)(V_e . e) < 0 with
        # e = (cos t, sin t) is cos(2t - phi_s - phi_e) < -cos(phi_s - phi_e), an arc of width pi - alpha,
        # alpha = arccos(-cos(phi_s - phi_e)): only the grid angles of that arc (and one more each side,
        # then the sign test itself) are looked at, not all n
        vsx, vsy, vex, vey = st[0][2][:, :-1], st[1][2][:, :-1], st[0][2][:, 1:], st[1][2][:, 1:]
        ps_, pe_ = np.arctan2(vsy, vsx), np.arctan2(vey, vex)
        alpha = np.arccos(np.clip(-np.cos(ps_ - pe_), -1.0, 1.0))
        lo = (alpha + ps_ + pe_) / 2
        jlo = np.floor(lo * n_ang / np.pi).astype(np.int64) - 1
        cnt = np.minimum(np.ceil((np.pi - alpha) * n_ang / np.pi).astype(np.int64) + 3, n_ang)      # (N, M)
        pi_, pj_ = np.nonzero(cnt > 0)
        cc = cnt[pi_, pj_]
        nn_, jx = np.repeat(pi_, cc), np.repeat(pj_, cc)
        start = np.repeat(np.cumsum(cc) - cc, cc)
        aa = (np.repeat(jlo[pi_, pj_], cc) + np.arange(cc.sum()) - start) % n_ang
        c, sn = cs[0, aa], cs[1, aa]
        keep = (c * vsx[nn_, jx] + sn * vsy[nn_, jx]) * (c * vex[nn_, jx] + sn * vey[nn_, jx]) < 0
        pk = peak[p[nn_], aa]
        keep &= penv[nn_, jx] > pk
        pr = lambda k: np.abs(c * st[0][1][nn_, jx + k] + sn * st[1][1][nn_, jx + k]) * omega[p[nn_]]   # noqa: E731
        keep &= np.maximum(pr(0), pr(1)) + rise[nn_, jx] > pk
        nn_, jx, aa = nn_[keep], jx[keep], aa[keep]
        if not nn_.size:
            continue
        rr, pp = r[nn_], p[nn_]
        ds = S[nn_, jx + 1] - S[nn_, jx]
        gd = (g1[rr] - g0[rr]) / h[rr][:, None]                             # (K, 2)
        D = [_taylor(st[ci][1][nn_, jx], st[ci][2][nn_, jx], st[ci][3][nn_, jx], gd[:, ci], omega[pp], zeta[pp], ds)
             for ci in (0, 1)]
        C = (cs[0, aa][:, None] * D[0] + cs[1, aa][:, None] * D[1]) * (omega[pp] ** 2)[:, None]   # omega^2 u_theta
        val = _poly_peak(C, np.zeros(nn_.size), np.ones(nn_.size))
        np.maximum.at(peak, (pp, aa), val)
    return peak


def _rotated_peaks(h, cs, n_probe=16):
    """max over rows of |h[:, 0] cos + h[:, 1] sin| for h (rows, 2, P): (P, n_angles).

    Exact pruning: the n_probe rows of largest radius r = |(h0, h1)| give, per period, a
    lower bound L on every angle's peak; a row with r < L projects below L at every angle,
    so only the rows with r >= L (typically a few percent) are projected."""
    r = np.hypot(h[:, 0], h[:, 1])                                    # (rows, P)
    probe = np.argsort(r, axis=0)[-n_probe:]                          # (m, P)
    hp = np.take_along_axis(h, probe[:, None, :], axis=0)             # (m, 2, P)
    lower = np.abs(np.einsum("mcp,ca->pma", hp, cs)).max(axis=1).min(axis=1)
    out = np.empty((h.shape[2], cs.shape[1]))
    for p in range(h.shape[2]):
        out[p] = np.abs(h[r[:, p] >= lower[p], :, p] @ cs).max(axis=0)
    return out


def _same_grid(a, b):
    for name in ("periods", "damping"):
        x, y = getattr(a, name), getattr(b, name)
        if x.shape != y.shape or not np.allclose(x, y, rtol=1e-12, atol=0.0):
            raise SpectrumInputError(f"the two spectra have different {name} "
                                     f"({x.size} vs {y.size} values or different values)")


def geometric_mean(spec_x, spec_y):
    """sqrt(x y) of two as-recorded component spectra on the same grid, for every quantity
    both hold."""
    _same_grid(spec_x, spec_y)
    names = [q for q in spec_x.quantities if q in spec_y.values]
    return ResponseSpectrum(spec_x.periods, spec_x.damping,
                            {q: np.sqrt(spec_x[q] * spec_y[q]) for q in names},
                            units=dict(spec_x.units), label="geometric mean")


def spectral_ratio(spec_a, spec_b):
    """a / b (e.g. SSI over fixed base) for every quantity both hold, units "-"; nan where
    b is 0 (e.g. SD at T = 0).  SpectrumInputError unless periods and damping agree."""
    _same_grid(spec_a, spec_b)
    names = [q for q in spec_a.quantities if q in spec_b.values]
    values = {}
    with np.errstate(divide="ignore", invalid="ignore"):
        for q in names:
            values[q] = np.where(spec_b[q] != 0, spec_a[q] / spec_b[q], np.nan)
    units = {**UNITS, **{q: "-" for q in names}}
    return ResponseSpectrum(spec_a.periods, spec_a.damping, values, units=units, label="ratio")


# ----------------------------------------------------------------------------- output
def write_csv(path, spectrum):
    """One row per (damping, period); header names every column with its unit, e.g.
    ``period [s],damping [-],SA [m/s^2],PSA [m/s^2],PSV [m/s],SD [m],SV [m/s]``."""
    names = spectrum.quantities
    u = spectrum.units
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([f"period [{u['period']}]", f"damping [{u['damping']}]"]
                   + [f"{q} [{u[q]}]" for q in names])
        for i, z in enumerate(spectrum.damping):
            for j, T in enumerate(spectrum.periods):
                w.writerow([repr(float(T)), repr(float(z))]
                           + [repr(float(spectrum[q][i, j])) for q in names])


def plot(path_png, spectra, labels=None, quantity="PSA"):
    """One curve per spectrum and damping ratio of ``quantity`` against period on a log axis
    (T = 0 is left out), written to ``path_png`` with the Agg backend; labels default to
    the spectra's own."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    spectra = [spectra] if isinstance(spectra, ResponseSpectrum) else list(spectra)
    labels = [s.label for s in spectra] if labels is None else list(labels)
    if len(labels) != len(spectra):
        raise SpectrumInputError(f"{len(spectra)} spectra but {len(labels)} labels")
    fig = Figure(figsize=(7, 4.5))
    FigureCanvasAgg(fig)            # Agg, without pyplot's global state
    ax = fig.add_subplot()
    for s, lab in zip(spectra, labels):
        if quantity not in s.values:
            raise SpectrumInputError(f"spectrum {lab!r} has no {quantity}")
        order = np.argsort(s.periods)
        keep = order[s.periods[order] > 0]
        for i, z in enumerate(s.damping):
            ax.plot(s.periods[keep], s[quantity][i, keep],
                    label=f"{lab}, zeta = {z:g}" if s.damping.size > 1 else lab)
    ax.set_xscale("log")
    ax.set_xlabel(f"period T [{UNITS['period']}]")
    ax.set_ylabel(f"{quantity} [{spectra[0].units[quantity]}]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path_png, dpi=120)
    return path_png
