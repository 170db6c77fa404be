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
    Peaks are taken over the samples (and the ``oversample`` sub-steps), never between
    them: that is the only error.  A peak between samples is missed by at most
    1 - cos(omega dt / 2) ~ (omega dt)^2 / 8 relative, so for T < ~10 dt ask for
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


def response_spectrum(t, acc, periods=None, damping=(0.05,), quantity="all", oversample=1):
    """Response spectra of the ground acceleration ``acc`` [m/s^2] sampled at ``t`` [s].

    periods [s] (default ``standard_periods()``; 0 allowed: rigid limit), damping ratios
    in [0, 1), quantity "all" or names from QUANTITIES, oversample sub-steps per sample
    step.  Returns a ResponseSpectrum with arrays (n_damping, n_periods); peaks at the
    samples and sub-steps (module docstring)."""
    t, acc = _check_series(t, acc)
    periods, damping = _check_grid(periods, damping)
    names = _check_quantity(quantity)
    k = _check_int("oversample", oversample)
    omega, zeta, pos = _pairs(periods, damping)
    pd, pv, pa = np.zeros(omega.size), np.zeros(omega.size), np.zeros(omega.size)
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
         oversample=1):
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
    peak = np.zeros((omega.size, n))                              # peak |omega^2 u_theta|
    for y0, _ in _march(t, np.stack([ax, ay]), omega, zeta, _check_int("oversample", oversample)):
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
