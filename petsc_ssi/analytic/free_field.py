r"""Free field of a homogeneous elastic half-space under plane seismic waves (pure numpy/scipy).

The known total field u_ff of the scattered-field formulation (seismic input): incident plane P,
SV or SH waves and their free-surface reflections, and plane Rayleigh waves, at the surface and at
depth, in the time domain, for any incident time function.  No PETSc and no other petsc_ssi module
is imported, so everything here is testable alone (``tests/analytic/test_free_field.py``).

Conventions
-----------
Soil in z < 0, free surface z = 0, e_z UP, depth d = -z.  alpha = c_p, beta = c_s,
kappa = alpha/beta (> sqrt(4/3), i.e. Poisson's ratio nu in (-1, 1/2)), mu = rho beta^2,
lambda = rho alpha^2 - 2 mu.  Angles are given in DEGREES.  The horizontal propagation direction is
e_h = (cos psi, sin psi, 0) (psi = ``azimuth``), the transverse one e_t = e_z x e_h =
(-sin psi, cos psi, 0).  Vertical displacement u_v is positive UP.  Complex coefficients use the
time factor e^{-i omega t} (numpy's FFT, e^{+i omega t}, needs conj on positive frequencies).

Every field is a sum of plane-wave terms

    u = Re sum_k  C_k d_k U(t - t0 - s_k . (x - x0))              (1)

with s_k = p e_h + q_k e_z the slowness vector (p = 1/c_app, Snell), d_k the polarisation (complex
for evanescent terms), C_k the amplitude per unit controlled motion and U = g - i H[g] the analytic
signal of the time function g (only positive frequencies in the e^{-i omega t} convention; H the
standard Hilbert transform, H[cos] = sin, ``scipy.signal.hilbert(g).imag``).  When C_k d_k and q_k
are real (every pre-critical body-wave term), Re(C d U) = C d g: no Hilbert transform is needed.
An evanescent term has q_k = q_r - i q_i (q_i >= 0); at depth d its argument is the complex time
tau - i a with a = q_i d >= 0, where U is continued analytically (each frequency decays as
e^{-omega a}).  Re U(tau - i a) is the Poisson-smoothed g and -Im U the smoothed H[g].

Incident and reflected terms (Aki & Richards 2002, sec. 5.2; derived again below), tau_h = tau at the
surface projection, (h, z) components along (e_h, e_z), Snell sin i / alpha = sin j / beta = p:

    P :  d_P = (sin i,  cos i) g(tau_h + d cos i/alpha)          (incident, along s)
       + R_PP (sin i, -cos i) g(tau_h - d cos i/alpha) + R_PS (cos j, sin j) g(tau_h - d cos j/beta)
    SV:  d_SV = (cos j, -sin j) g(tau_h + d cos j/beta)          (horizontal part forward)
       + R_SS (cos j, sin j) g(tau_h - d cos j/beta) + R_SP (sin i, -cos i) g(tau_h - d cos i/alpha)
    SH:  e_t [g(tau_h + d cos j/beta) + g(tau_h - d cos j/beta)]   (R = 1, no conversion)

    D' = sin 2i sin 2j + kappa^2 cos^2 2j
    R_PP = (sin 2i sin 2j - kappa^2 cos^2 2j)/D',   R_PS = 2 kappa sin 2i cos 2j / D'
    R_SS = (kappa^2 cos^2 2j - sin 2i sin 2j)/D',   R_SP = 2 kappa sin 2j cos 2j / D'

Derivation sketch: the stress of one term of (1) is

    sigma = -Re{ C U'(.) [lambda (d.s) I + mu (d (x) s + s (x) d)] }                      (2)

(SEM2DPACK's plane-wave source uses the same expression); sigma e_z = 0 at z = 0 for all t gives
two linear equations for the two reflected amplitudes, solved by Cramer's rule above.  Surface
amplitudes per unit incident displacement, u_ff = A_h e_h g + A_v e_z g + A_t e_t g:

    vertical S: A_h = 2;  vertical P: A_v = 2;  SH: A_t = 2 (all angles)
    P : A_h = 2 kappa sin 2i cos j / D',      A_v = 2 kappa^2 cos i cos 2j / D'
    SV: A_h = 2 kappa^2 cos j cos 2j / D',    A_v = -2 kappa sin 2j cos i / D'

SV beyond the critical angle j_c = arcsin(1/kappa): sin i = kappa sin j > 1 and
cos i = +i sqrt(kappa^2 sin^2 j - 1) (the reflected P decays with depth for e^{-i omega t}); the
coefficients become complex and frequency independent, and by (1) the surface motion is
Re(A) g + Im(A) H[g].  A surface (outcrop) control record u of a component with complex coefficient
A is inverted by U_inc = U_rec / A, i.e. g_inc = (Re A u - Im A H[u]) / |A|^2.

Rayleigh waves: c_R = xi beta with xi in (0, 1) the root of
xi^6 - 8 xi^4 + (24 - 16/kappa^2) xi^2 - 16 (1 - 1/kappa^2) = 0 (the secular equation
(2 - xi^2)^2 = 4 b_s b_p squared, b_s = sqrt(1 - xi^2), b_p = sqrt(1 - xi^2/kappa^2)).  The
field is a P term (d = alpha s_P) and an S term (d = beta (q_S, -p)) with q = -i nu,
nu_P = b_p / c_R, nu_S = b_s / c_R; normalised to unit vertical surface motion, per harmonic
e^{-i omega tau} with k = omega / c_R (derived here from (2), checked by the tests):

    u_v(d) = [2 e^{-k b_s d} - (2 - xi^2) e^{-k b_p d}] / xi^2
    u_h(d) = -i [(2 - xi^2) e^{-k b_p d} / b_p - 2 b_s e^{-k b_s d}] / xi^2

so at the surface A = (A_h, A_v) = (-i H/V, 1) with H/V = (1 - xi^2/2)/b_p, i.e. in the time domain
u_v = w(tau), u_h = -(H/V) H[w](tau) e_h (retrograde: at the crest the particle moves back).  The
horizontal eigenfunction changes sign at d = ln((2 - xi^2)/(2 b_p b_s)) / (k (b_p - b_s)).
"incident" control of a Rayleigh wave means g = w, the vertical surface motion.

Hilbert transforms
------------------
``hilbert_of(f, t_grid)`` computes H[f], and the analytic signal at complex time tau - i a, by a
zero-padded FFT convolution (no wrap-around) of the samples of f, f', f'' on a uniform grid with
the band-limited discrete kernels K_a[m] = (1 - e^{-w})/w, w = pi (a/dt + i m); at a = 0 this is
delta_m - i (1 - (-1)^m)/(pi m), the band-limited discrete Hilbert kernel.  Between samples:
cubic Hermite interpolation of each series with its derivative series (error ~ (omega dt)^4/384);
beyond a window of ``extend`` grid lengths on each side: the moment expansion
U(z) ~ -(i/pi) sum_n M_n / (z - t_ref)^{n+1}.  f must be ~0 at both ends of the grid.

The Hilbert transform of a causal pulse is acausal (a ~1/t precursor).  ``taper_before`` multiplies
H[f] by a C2 ramp that is 0 before taper_before - taper_width and 1 after taper_before, and reports
the largest |H[f]| it modifies (``tail_level``).  The taper acts on the surface (a = 0)
evaluations only; the evanescent terms at depth (post-critical P, Rayleigh) use the untapered
analytic signal, which is intrinsically acausal.

``Ricker`` has a closed form: the analytic signal of exp(-s^2) is w(-s) (Faddeeva function,
Abramowitz & Stegun 7.1.3; H[exp(-s^2)] = 2 Dawson(s)/sqrt(pi)), the Ricker wavelet is
-(1/2) d^2/ds^2 exp(-s^2), and w^{(n+1)} = -2 z w^{(n)} - 2 n w^{(n-1)} (A&S 7.1.20), with the
asymptotic series (A&S 7.1.23) for |z| >= 8.

Causality: with a causal g (zero for t <= start),
``pw.t0 = pw.auto_start(points, dt)`` makes the surface field exactly zero for t <= 0 at the
given points, including the support of a tapered Hilbert transform (``support_start``).  An
untapered H (``Ricker``, ``support_start = -inf``) is not counted.

Sources
-------
* The formulas above are this module's own derivation: every one is re-checked in
  ``tests/analytic/test_free_field.py`` by an independent 2x2 solve of the free-surface conditions,
  the energy balance, and the traction-free and Navier checks.
* K. Aki & P. G. Richards (2002), Quantitative Seismology, 2nd ed., sec. 5.2 (free-surface
  reflection coefficients, D = (1/beta^2 - 2p^2)^2 + 4 p^2 cos i cos j/(alpha beta) = D'/(kappa^2
  beta^4)) [recalled, not re-read].
* J. D. Achenbach (1973), Wave Propagation in Elastic Solids, ch. 5 (Rayleigh waves) [recalled].
* M. Abramowitz & I. A. Stegun (1964), Handbook of Mathematical Functions, 7.1 (w(z)) [recalled;
  the formulas used are checked against scipy in the tests].
"""
import math

import numpy as np
from scipy import optimize, signal, special

__all__ = [
    "FreeFieldError", "Ricker", "Sin4Pulse", "HilbertTransform", "hilbert_of", "PlaneWave",
    "reflection_coefficients", "surface_amplitudes", "critical_angle", "rayleigh_speed",
    "rayleigh_hv", "WAVES",
]

WAVES = ("vertical_s", "vertical_p", "sh", "sv", "p", "rayleigh")
COMPONENTS = {"horizontal": 0, "vertical": 1, "transverse": 2}
AUTO_COMPONENT = {"vertical_s": "horizontal", "vertical_p": "vertical", "sh": "transverse",
                  "sv": "horizontal", "p": "vertical", "rayleigh": "vertical"}
ZERO_COEFF = 1e-8            # |controlled coefficient| below this (per unit incident) is refused
_SQPI = math.sqrt(math.pi)


class FreeFieldError(ValueError):
    """Invalid plane-wave free-field input (one-line message)."""


# ----------------------------------------------------------------------------- material ---
def _kappa(cs, cp):
    """kappa = cp/cs after checking the speeds (nu in (-1, 1/2) <=> kappa > sqrt(4/3))."""
    for name, c in (("cs", cs), ("cp", cp)):
        if not (np.isscalar(c) and np.isfinite(c) and c > 0):
            raise FreeFieldError(f"{name} must be a positive finite speed, got {c!r}")
    k = cp / cs
    if not k > math.sqrt(4.0 / 3.0):
        raise FreeFieldError(f"cp/cs = {k:.6g} <= sqrt(4/3): Poisson's ratio outside (-1, 0.5)")
    return k


def critical_angle(cs, cp):
    """SV critical angle j_c = arcsin(cs/cp) in degrees."""
    return math.degrees(math.asin(1.0 / _kappa(cs, cp)))


def _angle(angle):
    if not (np.isscalar(angle) and np.isfinite(angle) and 0.0 <= angle < 90.0):
        raise FreeFieldError(f"incidence angle must be in [0, 90) degrees, got {angle!r}")
    return math.radians(angle)


def _p_angles(i, k):
    """P incident at i: (sin i, cos i, sin j, cos j), all real."""
    sj = math.sin(i) / k
    return math.sin(i), math.cos(i), sj, math.sqrt(1.0 - sj * sj)


def _sv_angles(j, k):
    """SV incident at j: (sin i, cos i, sin j, cos j); cos i = +i sqrt(.) beyond j_c."""
    si = k * math.sin(j)
    ci = math.sqrt(1.0 - si * si) if si <= 1.0 else 1j * math.sqrt(si * si - 1.0)
    return si, ci, math.sin(j), math.cos(j)


def _dprime(si, ci, sj, cj, k):
    s2i, s2j, c2j = 2 * si * ci, 2 * sj * cj, 1 - 2 * sj * sj
    return s2i, s2j, c2j, s2i * s2j + k * k * c2j * c2j


def _reflection(wave, th, k):
    """(R_PP, R_PS) for wave "p", (R_SS, R_SP) for "sv"; th in radians."""
    ang = _p_angles(th, k) if wave == "p" else _sv_angles(th, k)
    s2i, s2j, c2j, D = _dprime(*ang, k)
    if wave == "p":
        return (s2i * s2j - k * k * c2j ** 2) / D, 2 * k * s2i * c2j / D
    return (k * k * c2j ** 2 - s2i * s2j) / D, 2 * k * s2j * c2j / D


def reflection_coefficients(wave, angle, cs, cp):
    """Free-surface reflection coefficients for the polarisations of the module docstring.

    wave "p": (R_PP, R_PS); "sv": (R_SS, R_SP) (complex beyond the critical angle);
    "sh": (1.0, 0.0).  angle in degrees.
    """
    k, th = _kappa(cs, cp), _angle(angle)
    if wave == "sh":
        return 1.0, 0.0
    if wave not in ("p", "sv"):
        raise FreeFieldError(f"reflection_coefficients: wave must be 'p', 'sv' or 'sh', "
                             f"got {wave!r}")
    return _reflection(wave, th, k)


def surface_amplitudes(wave, angle, cs, cp):
    """(A_h, A_v, A_t) per unit incident displacement (closed forms, sec. 2.2-2.5 of the note).

    Rayleigh: per unit vertical surface motion, (-i H/V, 1, 0).
    """
    k, th = _kappa(cs, cp), _angle(angle)
    if wave in ("vertical_s",):
        return 2.0, 0.0, 0.0
    if wave == "vertical_p":
        return 0.0, 2.0, 0.0
    if wave == "sh":
        return 0.0, 0.0, 2.0
    if wave == "rayleigh":
        return -1j * rayleigh_hv(cs, cp), 1.0, 0.0
    if wave not in ("p", "sv"):
        raise FreeFieldError(f"unknown wave {wave!r}; expected one of {', '.join(WAVES)}")
    si, ci, sj, cj = ang = _p_angles(th, k) if wave == "p" else _sv_angles(th, k)
    s2i, s2j, c2j, D = _dprime(*ang, k)
    if wave == "p":
        return 2 * k * s2i * cj / D, 2 * k * k * ci * c2j / D, 0.0
    return 2 * k * k * cj * c2j / D, -2 * k * s2j * ci / D, 0.0


# ----------------------------------------------------------------------------- Rayleigh ---
def _rayleigh_xi(k):
    """xi = c_R/beta: the cubic's root in (0, 1), checked against bracketing of the secular eq."""
    roots = np.roots([1.0, -8.0, 24.0 - 16.0 / k ** 2, -16.0 * (1.0 - 1.0 / k ** 2)])
    x = [r.real for r in roots if abs(r.imag) < 1e-10 and 0.0 < r.real < 1.0]
    if len(x) != 1:
        raise FreeFieldError(f"Rayleigh cubic has {len(x)} roots in (0, 1) for cp/cs = {k:.6g}")

    def secular(xi):       # (2 - xi^2)^2 - 4 b_s b_p, divided by xi^2 (xi = 0 is a trivial root)
        bs, bp = math.sqrt(1 - xi * xi), math.sqrt(1 - (xi / k) ** 2)
        return ((2 - xi * xi) ** 2 - 4 * bs * bp) / xi ** 2

    xb = optimize.brentq(secular, 1e-3, 1.0, xtol=1e-15, rtol=1e-15)
    xi = math.sqrt(x[0])
    if abs(xb - xi) > 1e-9:
        raise FreeFieldError(f"Rayleigh speed: cubic {xi!r} and bracketing {xb!r} disagree")
    return xi


def rayleigh_speed(cs, cp):
    """Rayleigh-wave speed c_R (same units as cs)."""
    return cs * _rayleigh_xi(_kappa(cs, cp))


def rayleigh_hv(cs, cp):
    """Surface H/V amplitude ratio of the Rayleigh wave, (1 - xi^2/2)/sqrt(1 - xi^2/kappa^2)."""
    k = _kappa(cs, cp)
    xi = _rayleigh_xi(k)
    return (1 - xi * xi / 2) / math.sqrt(1 - (xi / k) ** 2)


# ------------------------------------------------------------------------ time functions ---
def _faddeeva_derivs(z, nmax):
    """[w, w', ..., w^(nmax)] of the Faddeeva function for Im z >= 0 (recurrence / asymptotic)."""
    z = np.asarray(z, complex)
    out = np.empty((nmax + 1,) + z.shape, complex)
    big = np.abs(z) >= 8.0
    if (~big).any():
        zs = z[~big]
        w = [special.wofz(zs), None]
        w[1] = -2 * zs * w[0] + 2j / _SQPI
        for n in range(1, nmax):
            w.append(-2 * zs * w[n] - 2 * n * w[n - 1])
        for n in range(nmax + 1):
            out[n][~big] = w[n]
    if big.any():
        zb = z[big]
        kk = np.arange(60)
        ck = np.cumprod(np.r_[1.0, (2 * kk[1:] - 1) / 2.0])          # (2k-1)!!/2^k
        for n in range(nmax + 1):
            pn = np.prod([2 * kk + 1 + m for m in range(n)], axis=0) if n else np.ones(60)
            coef = (-1) ** n * ck * pn
            out[n][big] = (1j / _SQPI) * np.polyval(coef[::-1], zb ** -2) * zb ** -(n + 1)
    return out


class Ricker:
    """Ricker wavelet g(t) = (1 - 2 s^2) exp(-s^2), s = pi fc (t - t_peak), times ``amplitude``.

    Protocol: ``g(t, deriv=0)`` (deriv 0, 1, 2 analytic).  Closed-form Hilbert transform
    ``hilbert(t, deriv)`` and analytic signal ``analytic(t, a, deriv)`` = U^(deriv)(t - i a),
    a >= 0.
    """
    support_start = -math.inf

    def __init__(self, fc, t_peak=None, amplitude=1.0):
        if not (np.isfinite(fc) and fc > 0):
            raise FreeFieldError(f"Ricker: fc must be positive, got {fc!r}")
        self.fc, self.amplitude = float(fc), float(amplitude)
        self.t_peak = 1.5 / fc if t_peak is None else float(t_peak)

    def __call__(self, t, deriv=0):
        s = math.pi * self.fc * (np.asarray(t, float) - self.t_peak)
        s2, e = s * s, np.exp(-s * s)
        poly = {0: 1 - 2 * s2, 1: 4 * s * s2 - 6 * s, 2: -8 * s2 * s2 + 24 * s2 - 6}[deriv]
        return self.amplitude * (math.pi * self.fc) ** deriv * poly * e

    def analytic(self, t, a=0.0, deriv=0):
        """U^(deriv)(t - i a) = -(1/2) (-pi fc)^deriv w^(deriv+2)(-s),
        s = pi fc (t - i a - t_peak)."""
        a = np.asarray(a, float)
        if np.any(a < 0):
            raise FreeFieldError("analytic signal needs a >= 0 (lower half of the complex t plane)")
        s = math.pi * self.fc * (np.asarray(t, float) - 1j * a - self.t_peak)
        w = _faddeeva_derivs(-s, deriv + 2)[deriv + 2]
        return -0.5 * self.amplitude * (-math.pi * self.fc) ** deriv * w

    def hilbert(self, t, deriv=0):
        return -self.analytic(t, 0.0, deriv).imag


class Sin4Pulse:
    """Causal C3 pulse amplitude sin^4(pi (t - t_start)/duration) on [t_start, t_start + duration].

    Protocol ``g(t, deriv=0)``; zero outside the interval.  A convenient causal test input.
    """
    def __init__(self, duration, t_start=0.0, amplitude=1.0):
        if not (np.isfinite(duration) and duration > 0):
            raise FreeFieldError(f"Sin4Pulse: duration must be positive, got {duration!r}")
        self.duration, self.t_start = float(duration), float(t_start)
        self.amplitude = float(amplitude)

    def __call__(self, t, deriv=0):
        t = np.asarray(t, float)
        om = math.pi / self.duration
        th = om * (t - self.t_start)
        S, C = np.sin(th), np.cos(th)
        val = {0: S ** 4, 1: 4 * om * S ** 3 * C,
               2: 4 * om * om * S * S * (3 * C * C - S * S)}[deriv]
        inside = (t > self.t_start) & (t < self.t_start + self.duration)
        return self.amplitude * np.where(inside, val, 0.0)


# --------------------------------------------------------------------- Hilbert by FFT ---
def _phi(w):
    """(1 - e^{-w})/w and its derivative (e^{-w}(1 + w) - 1)/w^2, stable near w = 0."""
    w = np.asarray(w, complex)
    small = np.abs(w) < 1.0
    ws = np.where(small, 1.0, w)
    f = np.where(small, 1.0, -np.expm1(-ws) / ws)
    d = np.where(small, 0.0, (np.exp(-ws) * (1 + ws) - 1) / ws ** 2)
    if small.any():
        k = np.arange(1, 22)
        fac = np.cumprod(np.arange(2, 24, dtype=float))             # (k+1)! for k = 1..22
        wsm = w[small]
        f_s = 1 + sum((-1) ** m * wsm ** m / fac[m - 1] for m in range(1, 21))
        d_s = sum((-1) ** m * m * wsm ** (m - 1) / fac[m - 1] for m in k)
        f[small], d[small] = f_s, d_s
    return f, d


def _hermite(y, dy, t_first, dt, t):
    """Cubic Hermite interpolation of uniform series (y, dy) at t (inside the grid)."""
    x = (t - t_first) / dt
    j = np.clip(np.floor(x).astype(int), 0, len(y) - 2)
    u = x - j
    h00, h10 = (1 + 2 * u) * (1 - u) ** 2, u * (1 - u) ** 2
    h01, h11 = u * u * (3 - 2 * u), u * u * (u - 1)
    return h00 * y[j] + h10 * dt * dy[j] + h01 * y[j + 1] + h11 * dt * dy[j + 1]


class HilbertTransform:
    """H[f] (protocol ``h(t, deriv=0)``) and the analytic signal of f at complex time.

    Built by ``hilbert_of``.  Attributes: ``support_start`` (-inf, or taper_before - taper_width),
    ``tail_level`` (largest |H[f]| at t <= taper_before, i.e. the precursor the taper modifies; 0
    without taper).
    """
    N_MOMENTS = 12

    def __init__(self, f, t_grid, taper_before=None, taper_width=None, extend=4.0):
        t = np.asarray(t_grid, float)
        if t.ndim != 1 or t.size < 8 or not np.all(np.isfinite(t)):
            raise FreeFieldError("hilbert_of: t_grid must be a finite 1-D grid of >= 8 times")
        dt = (t[-1] - t[0]) / (t.size - 1)
        if not dt > 0 or np.max(np.abs(np.diff(t) - dt)) > 1e-9 * dt:
            raise FreeFieldError("hilbert_of: t_grid must be uniform and increasing")
        self.dt, self._n, self._ne = dt, t.size, int(math.ceil(extend * t.size))
        self._t_first = t[0] - self._ne * dt
        self._samples = [np.asarray(f(t, d), float) for d in range(3)]
        self._t_ref = 0.5 * (t[0] + t[-1])
        pw = (t - self._t_ref)[None, :] ** np.arange(self.N_MOMENTS)[:, None]
        self._moments = [dt * pw @ g for g in self._samples]
        self._t_last = self._t_first + (self._n + 2 * self._ne - 1) * dt
        self._cache = {}
        self._set_taper(taper_before, taper_width)

    # --- grid series of U^(n)(t_m - i a) and its derivative, n = 0, 1, 2
    def _series(self, a):
        key = float(a)
        if key not in self._cache:
            n, ne, dt = self._n, self._ne, self.dt
            m = np.arange(-(n - 1 + ne), n + ne)
            phi, dphi = _phi(math.pi * (key / dt + 1j * m))
            K, dK = phi, 1j * (math.pi / dt) * dphi
            cut = slice(n - 1, 2 * n - 1 + 2 * ne)
            self._cache[key] = [(signal.fftconvolve(g, K)[cut], signal.fftconvolve(g, dK)[cut])
                                for g in self._samples]
        return self._cache[key]

    def _tail(self, z, deriv):
        """Moment expansion U^(deriv)(z) ~ -(i/pi) sum M_n / (z - t_ref)^{n+1} (outside)."""
        zz = z - self._t_ref
        return (-1j / math.pi) * sum(M / zz ** (j + 1) for j, M in enumerate(self._moments[deriv]))

    def analytic(self, t, a=0.0, deriv=0):
        """U^(deriv)(t - i a) = (f - i H[f])^(deriv) continued to t - i a (a >= 0), untapered."""
        t = np.asarray(t, float)
        a = np.broadcast_to(np.asarray(a, float), t.shape)
        if np.any(a < 0):
            raise FreeFieldError("analytic signal needs a >= 0 (lower half of the complex t plane)")
        out = np.empty(t.shape, complex)
        inside = (t >= self._t_first) & (t <= self._t_last)
        for av in np.unique(a):
            sel = a == av
            y, dy = self._series(av)[deriv]
            si, so = sel & inside, sel & ~inside
            out[si] = _hermite(y, dy, self._t_first, self.dt, t[si])
            out[so] = self._tail(t[so] - 1j * av, deriv)
        return out

    # --- taper of the acausal precursor (a = 0 only)
    def _set_taper(self, before, width):
        self.taper_before, self.taper_width = before, width
        self.support_start, self.tail_level = -math.inf, 0.0
        if before is None:
            return
        w = 20 * self.dt if width is None else float(width)
        if not (np.isfinite(before) and np.isfinite(w) and w >= 0):
            raise FreeFieldError("hilbert_of: taper_before/taper_width must be finite, width >= 0")
        self.taper_before, self.taper_width = float(before), w
        self.support_start = self.taper_before - w
        tg, h = self._grid_values()
        pre = tg <= self.taper_before
        self.tail_level = float(np.max(np.abs(h[pre]))) if pre.any() else 0.0
        if tg[0] > self.taper_before:     # precursor beyond the window: the tail's value there
            self.tail_level = float(abs(self._tail(np.array([self.taper_before]), 0).imag[0]))

    def _grid_values(self):
        """(times, untapered H[f]) on the computed window's grid."""
        return self._t_first + self.dt * np.arange(self._n + 2 * self._ne), -self._series(0.0)[0][0].imag

    def set_taper(self, before, width=None):
        """Taper the acausal precursor before ``before`` (a C2 ramp of ``width``, default 20 dt, ending
        there; None: no taper). Sets ``support_start`` and ``tail_level``."""
        self._set_taper(before, width)

    def quiet_before(self, tol, start=0.0):
        """The latest time tau_b <= ``start`` before which the untapered |H[f]| stays within ``tol``
        times its largest value (on the computed window, and by the moment expansion beyond it),
        or None where it does not before -1e6 (f's integral not finite there)."""
        tg, h = self._grid_values()
        h = np.abs(h)
        lim = float(tol) * float(h.max())
        if not lim > 0:
            return float(start)
        above = np.nonzero(h > lim)[0]
        if above[0] > 0:
            return float(min(tg[above[0] - 1], start))
        t = min(tg[0], -1.0)              # the window's first point already exceeds: the tail, further out
        while abs(self._tail(np.array([t]), 0).imag[0]) > lim:
            t *= 2.0
            if t < -1e6:
                return None
        return float(min(t, start))

    def _window(self, t):
        """C2 ramp W (0 before support_start, 1 after taper_before) and W', W''."""
        w = self.taper_width
        if w == 0:
            return (t > self.taper_before).astype(float), 0 * t, 0 * t
        s = np.clip((t - self.support_start) / w, 0.0, 1.0)
        return (s ** 3 * (10 - 15 * s + 6 * s * s), 30 * s * s * (1 - s) ** 2 / w,
                60 * s * (1 - s) * (1 - 2 * s) / w ** 2)

    def __call__(self, t, deriv=0):
        t = np.asarray(t, float)
        if self.taper_before is None:
            return -self.analytic(t, 0.0, deriv).imag
        h = [-self.analytic(t, 0.0, d).imag for d in range(deriv + 1)]
        W = self._window(t)
        return sum(math.comb(deriv, m) * W[deriv - m] * h[m] for m in range(deriv + 1))


def hilbert_of(f, t_grid, taper_before=None, taper_width=None, extend=4.0):
    """H[f] of a time function f(t, deriv) by zero-padded FFT on the uniform grid t_grid.

    Returns a ``HilbertTransform``: callable h(t, deriv=0) (deriv 0, 1, 2; cubic Hermite between
    samples using the derivative series), with ``analytic(t, a, deriv)`` for the evanescent terms.
    ``taper_before``: taper the acausal tail before that time (C2 ramp of ``taper_width``, default
    20 dt, ending at taper_before).  ``extend``: the computed window reaches extend*(grid length)
    beyond each end; farther out a 12-moment expansion is used.
    """
    return HilbertTransform(f, t_grid, taper_before, taper_width, extend)


class _OwnHilbert:
    """Adapter for time functions with closed-form ``hilbert``/``analytic`` (e.g. ``Ricker``)."""
    def __init__(self, g):
        self._g = g
        self.support_start = getattr(g, "support_start", -math.inf)

    def __call__(self, t, deriv=0):
        return self._g.hilbert(t, deriv)

    def analytic(self, t, a=0.0, deriv=0):
        return self._g.analytic(t, a, deriv)


# ------------------------------------------------------------------------- plane waves ---
def _body_terms(wave, th, k, cs, cp):
    """[(amplitude, polarisation (h, z, t), q)] per unit incident displacement, and p."""
    if wave in ("vertical_s", "vertical_p"):
        wave, th = ("sv" if wave == "vertical_s" else "p"), 0.0
    if wave == "sh":
        c = math.cos(th)
        return [(1.0, (0, 0, 1), c / cs), (1.0, (0, 0, 1), -c / cs)], math.sin(th) / cs
    if wave == "p":
        si, ci, sj, cj = _p_angles(th, k)
        rpp, rps = _reflection("p", th, k)
        return [(1.0, (si, ci, 0), ci / cp), (rpp, (si, -ci, 0), -ci / cp),
                (rps, (cj, sj, 0), -cj / cs)], si / cp
    si, ci, sj, cj = _sv_angles(th, k)
    rss, rsp = _reflection("sv", th, k)
    return [(1.0, (cj, -sj, 0), cj / cs), (rss, (cj, sj, 0), -cj / cs),
            (rsp, (si, -ci, 0), -ci / cp)], sj / cs


def _rayleigh_terms(k, cs, cp):
    """P and S terms of the Rayleigh wave, unit vertical surface motion (module docstring)."""
    xi = _rayleigh_xi(k)
    p = 1.0 / (xi * cs)
    qp, qs = -1j * math.sqrt(p * p - 1 / cp ** 2), -1j * math.sqrt(p * p - 1 / cs ** 2)
    X = -(2 * p * p * cs * cs - 1) / qp                  # alpha B_P
    Y = 2 * p * qp * X / (2 * p * p - 1 / cs ** 2)       # beta B_S
    return [(X, (p, qp, 0), qp), (Y, (qs, -p, 0), qs)], p


class PlaneWave:
    """Free field of one plane wave on the half-space z <= 0 (see the module docstring).

    wave: "vertical_s", "vertical_p", "sh", "sv", "p", "rayleigh".  cs, cp: wave speeds; g: time
    function g(t, deriv); angle: incidence from the vertical (deg, [0, 90); must be 0 for the
    vertical waves and Rayleigh); azimuth psi (deg): e_h = (cos psi, sin psi, 0);
    polarisation (deg, "vertical_s" only): horizontal direction of the S motion (replaces psi);
    x0: control point (x, y) on the surface; t0: time shift (attribute; see ``auto_start``).
    control "surface": g is the surface motion of ``component`` at x0; "incident": g is the
    incident displacement (Rayleigh: the vertical surface motion).  component "auto" | "horizontal"
    (along e_h) | "vertical" | "transverse" (along e_t).  postcritical: allow SV beyond j_c.
    rho: density (for ``stress``).  hilbert / t_grid: H[g] provider (needed only when a coefficient
    is complex); default g's own closed form (``Ricker``) or ``hilbert_of(g, t_grid)``.

    Methods (points: (n, 3) array with z <= 0; t: scalar or 1-D array of nt times):
    ``displacement``, ``velocity``, ``acceleration`` -> (n, 3) or (nt, n, 3);
    ``stress`` -> (n, 3, 3) or (nt, n, 3, 3); ``surface_coefficients()`` -> (A_h, A_v, A_t);
    ``delay(points)`` -> (n,); ``auto_start(points, dt, start=0)`` -> t0.  Attributes: ``c_app``
    (inf at vertical incidence), ``p`` = 1/c_app, ``e_h``, ``e_t``, ``t0`` (settable).
    """

    def __init__(self, wave, cs, cp, g, angle=0.0, azimuth=0.0, polarisation=0.0, x0=(0.0, 0.0),
                 t0=0.0, control="surface", component="auto", postcritical=False, rho=None,
                 hilbert=None, t_grid=None):
        self._check_names(wave, control, component)
        self.kappa = k = _kappa(cs, cp)
        self.wave, self.cs, self.cp, self.g, self.t0 = wave, float(cs), float(cp), g, float(t0)
        th = _angle(angle)
        if wave in ("vertical_s", "vertical_p", "rayleigh") and th != 0.0:
            raise FreeFieldError(f"angle is not used by wave {wave!r}; got {angle!r} "
                                 f"(use 'sv' or 'p' for oblique incidence)")
        if wave == "sv" and k * math.sin(th) > 1.0 and not postcritical:
            raise FreeFieldError(f"SV at {angle:g} deg is beyond the critical angle "
                                 f"{critical_angle(cs, cp):.4f} deg; pass postcritical=True")
        psi = polarisation if wave == "vertical_s" else azimuth
        if not (np.isscalar(psi) and np.isfinite(psi)):
            raise FreeFieldError(f"azimuth/polarisation must be a finite angle in degrees, "
                                 f"got {psi!r}")
        psi = math.radians(psi)
        self.e_h = np.array([math.cos(psi), math.sin(psi), 0.0])
        self.e_t = np.array([-math.sin(psi), math.cos(psi), 0.0])
        self.x0 = self._control_point(x0)
        terms, self.p = (_rayleigh_terms(k, cs, cp) if wave == "rayleigh"
                         else _body_terms(wave, th, k, cs, cp))
        self.c_app = math.inf if self.p == 0 else 1.0 / self.p
        self.angle = float(angle)
        self._A = tuple(surface_amplitudes(wave, angle, cs, cp))
        self.component = AUTO_COMPONENT[wave] if component == "auto" else component
        self.control = control
        scale, surf = self._control_scale(control)
        self._set_terms(terms, scale, surf, rho)
        self._hil = self._hilbert_provider(hilbert, t_grid) if self.needs_hilbert else None

    # --- construction helpers
    @staticmethod
    def _check_names(wave, control, component):
        if wave not in WAVES:
            raise FreeFieldError(f"unknown wave {wave!r}; expected one of {', '.join(WAVES)}")
        if control not in ("surface", "incident"):
            raise FreeFieldError(f"unknown control {control!r}; expected 'surface' or 'incident'")
        if component != "auto" and component not in COMPONENTS:
            raise FreeFieldError(f"unknown component {component!r}; expected 'auto', "
                                 f"{', '.join(map(repr, COMPONENTS))}")

    @staticmethod
    def _control_point(x0):
        x0 = np.asarray(x0, float).ravel()
        if x0.size not in (2, 3) or not np.all(np.isfinite(x0)) or (x0.size == 3 and x0[2] != 0):
            raise FreeFieldError(f"x0 must be a finite surface point (x, y) or (x, y, 0), got {x0}")
        return x0[:2]

    def _control_scale(self, control):
        """1/A_ctrl and the surface coefficients (h, z, t) per unit controlled motion."""
        A = np.array(self._A, complex if any(np.iscomplexobj(a) for a in self._A) else float)
        if control == "incident":
            return 1.0, A
        idx = COMPONENTS[self.component]
        if abs(A[idx]) < ZERO_COEFF:
            raise FreeFieldError(f"{self.wave} at {self.angle:g} deg has no {self.component} "
                                 f"surface motion (coefficient {abs(A[idx]):.3g}); "
                                 f"control another component")
        surf = A / A[idx]
        surf[idx] = 1.0
        return 1.0 / A[idx], surf

    def _vec(self, c):
        """(h, z, t) coefficients -> global 3-vector."""
        return c[0] * self.e_h + c[1] * np.array([0, 0, 1.0]) + c[2] * self.e_t

    def _set_terms(self, terms, scale, surf, rho):
        s_of = [self.p * self.e_h + q * np.array([0, 0, 1.0]) for _, _, q in terms]
        self._V = [_real_if_real(scale * amp * self._vec(np.asarray(d))) for amp, d, _ in terms]
        self._q = [complex(q) for _, _, q in terms]
        self._Vs = _real_if_real(self._vec(surf))
        self.rho = rho
        if rho is not None:
            if not (np.isscalar(rho) and np.isfinite(rho) and rho > 0):
                raise FreeFieldError(f"rho must be a positive finite density, got {rho!r}")
            mu = rho * self.cs ** 2
            lam = rho * self.cp ** 2 - 2 * mu
            self._S = [_real_if_real(-(lam * (V @ s) * np.eye(3)
                                       + mu * (np.outer(V, s) + np.outer(s, V))))
                       for V, s in zip(self._V, s_of)]
        self.needs_hilbert = (any(np.iscomplexobj(v) for v in self._V + [self._Vs])
                              or any(q.imag != 0 for q in self._q))

    def _hilbert_provider(self, hilbert, t_grid):
        if hilbert is not None:
            return hilbert
        if hasattr(self.g, "hilbert") and hasattr(self.g, "analytic"):
            return _OwnHilbert(self.g)
        if t_grid is not None:
            return hilbert_of(self.g, t_grid)
        raise FreeFieldError(f"{self.wave} at {self.angle:g} deg needs H[g]: "
                             f"pass hilbert= or t_grid=")

    def taper_precursor(self, tol, width_frac=0.1):
        """Where the field needs H[g] computed from samples (``hilbert_of``): taper H[g]'s acausal
        precursor (a ~1/t tail before g starts) from the latest time before which |H[g]| stays within
        ``tol`` of its largest value (``HilbertTransform.quiet_before``), over a C2 ramp of
        ``width_frac`` of the precursor's length (at least 20 samples) ending there; ``auto_start``
        then starts the wave before the ramp. Returns (taper_before, width, tail_level: the largest
        |H[g]| the taper changes), or None where no H[g] is computed. Raises FreeFieldError where
        |H[g]| does not fall that low before t = -1e6."""
        if not self.needs_hilbert or not hasattr(self._hil, "quiet_before"):
            return None
        start = float(getattr(self.g, "t_start", 0.0))
        tb = self._hil.quiet_before(tol, start)
        if tb is None:
            raise FreeFieldError(f"H[g] does not fall below {tol:g} of its peak before t = -1e6: g does "
                                 f"not return to rest")
        width = max(20.0 * self._hil.dt, width_frac * (start - tb))
        self._hil.set_taper(tb, width)
        return tb, width, self._hil.tail_level

    # --- public API
    def surface_coefficients(self):
        """(A_h, A_v, A_t) per unit incident displacement (complex beyond j_c; Rayleigh: per unit
        vertical surface motion)."""
        return self._A

    def delay(self, points):
        """Earliest arrival-time offset p (x - x0).e_h + min_k Re(q_k) z at each point, (n,)."""
        X, z, surf = self._points(points)
        xh = (X[:, :2] - self.x0) @ self.e_h[:2]
        dz = np.min([q.real * z for q in self._q], axis=0)
        return self.p * xh + np.where(surf, 0.0, dz)

    def auto_start(self, points, dt, start=0.0):
        """Smallest t0 making the field 0 for t <= 0 at the points (g zero for t <= start), + dt."""
        s = start
        if self.needs_hilbert and np.isfinite(getattr(self._hil, "support_start", -math.inf)):
            s = min(s, self._hil.support_start)
        return float(-np.min(self.delay(points)) - s + dt)

    def displacement(self, points, t):
        return self._field(points, t, 0)

    def velocity(self, points, t):
        return self._field(points, t, 1)

    def acceleration(self, points, t):
        return self._field(points, t, 2)

    def stress(self, points, t):
        """Cauchy stress (Pa if SI), shape (n, 3, 3) or (nt, n, 3, 3); needs rho."""
        return self._stress(points, t, 1)

    def stress_integral(self, points, t):
        """The stress's running time integral int_{-inf}^t sigma dt' (Pa s if SI), shape as ``stress``: the
        stress is linear in the strain, which carries one time derivative of the signal (a plane wave is a
        function of t - s.x), so its integral is the same sum over the signal itself. The exact mean over
        a step is the difference of two values over the step (a source's piecewise-constant traction)."""
        return self._stress(points, t, 0)

    def _stress(self, points, t, deriv):
        if self.rho is None:
            raise FreeFieldError("stress needs the density: PlaneWave(..., rho=...)")
        X, z, _ = self._points(points)
        tt, scalar = _times(t)
        base = self._base(X, tt)
        out = np.zeros(base.shape + (3, 3))
        for S, q in zip(self._S, self._q):
            out += self._term(S, base - q.real * z, q.imag * z + 0 * base, deriv)
        return out[0] if scalar else out

    # --- evaluation
    def _points(self, points):
        X = np.asarray(points, float)
        if X.ndim != 2 or X.shape[1] != 3 or not np.all(np.isfinite(X)):
            raise FreeFieldError(f"points must be a finite (n, 3) array, got shape {X.shape}")
        ztol = 1e-9 * max(1.0, float(np.max(np.abs(X))) if X.size else 1.0)
        if np.any(X[:, 2] > ztol):
            raise FreeFieldError(f"points above the free surface z = 0 "
                                 f"(max z = {X[:, 2].max():.3g})")
        surf = X[:, 2] >= -ztol
        return X, np.where(surf, 0.0, X[:, 2]), surf

    def _base(self, X, tt):
        xh = (X[:, :2] - self.x0) @ self.e_h[:2]
        return tt[:, None] - self.t0 - self.p * xh[None, :]

    def _field(self, points, t, deriv):
        X, z, surf = self._points(points)
        tt, scalar = _times(t)
        base = self._base(X, tt)
        out = np.zeros(base.shape + (3,))
        if surf.any():
            bs = base[:, surf]
            out[:, surf] = self._term(self._Vs, bs, np.zeros_like(bs), deriv)
        deep = ~surf
        if deep.any():
            bd, zd = base[:, deep], z[deep]
            for V, q in zip(self._V, self._q):
                out[:, deep] += self._term(V, bd - q.real * zd, q.imag * zd + 0 * bd, deriv)
        return out[0] if scalar else out

    def _term(self, V, T, a, deriv):
        """Re[V U^(deriv)(T - i a)] for a coefficient array V (3,) or (3, 3); T, a shape (nt, m)."""
        re, im = self._signal(T, a, deriv, np.iscomplexobj(V) or np.any(a))
        ex = (slice(None),) * 2 + (None,) * np.ndim(V)
        out = re[ex] * np.real(V)
        if im is not None:
            out -= im[ex] * np.imag(V)
        return out

    def _signal(self, T, a, deriv, need_im):
        """(Re U, Im U) of the deriv-th derivative at complex time T - i a (a >= 0)."""
        re = _call(self.g, T, deriv)
        if not need_im:
            return re, None
        im = -_call(self._hil, T, deriv)
        deep = a > 0
        if deep.any():
            if not hasattr(self._hil, "analytic"):
                raise FreeFieldError("evanescent terms at depth need H[g] with .analytic "
                                     "(use hilbert_of or Ricker)")
            U = self._hil.analytic(T[deep], a[deep], deriv)
            re[deep], im[deep] = U.real, U.imag
        return re, im


def _real_if_real(v):
    v = np.asarray(v)
    return v.real.astype(float) if np.iscomplexobj(v) and not np.any(v.imag) else v


def _times(t):
    tt = np.asarray(t, float)
    if tt.ndim > 1 or not np.all(np.isfinite(tt)):
        raise FreeFieldError("t must be a finite scalar or 1-D array")
    return np.atleast_1d(tt), tt.ndim == 0


def _call(f, T, deriv):
    """f(T, deriv) on the flattened array, reshaped (time functions need only accept 1-D arrays)."""
    return np.asarray(f(T.ravel(), deriv), float).reshape(T.shape).copy()
