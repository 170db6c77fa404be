r"""How the structure's time integrators answer a harmonic load and free vibration (issue 46).

One oscillator, unit mass: u'' + c u' + k u = f(t), k = omega^2, c = alpha_m (C = alpha_m M);
step h = dt; a load of frequency f [Hz], Omega = 2 pi f, theta = Omega h = 2 pi f dt; W = omega h.
Each scheme of ``integrators.py`` is, per step, a linear map of its state y (green: (u, v after the
impulse); newmark: (u, v, a); midpoint: (u, v)) and of its load sample g^n:
    y^n = R y^{n-1} + L g^n.
``step_matrices`` transcribes each class's arithmetic on one dof (checked against the classes by
tests/fem/test_integrator_response.py). For g^n = G z^n, z = e^{i theta}, the steady state is
y^n = Y z^n with Y = (z I - R)^{-1} z L G; ``steady_ratio`` is its displacement over the exact one,
U = F / (k - Omega^2 + i c Omega), for f(t) = F e^{i Omega t}.

Load samples. green and newmark take g^n = the mean of f over the cell [t_n - h/2, t_n + h/2]
(fem/problem.py ``load``), i.e. G = F S, S = sin(theta/2)/(theta/2); midpoint takes the mean over
(t_{n-1}, t_n] (the BE traction's own basis), G = F S e^{-i theta/2}.

Closed forms (trapezoidal constants alpha = 1/4, delta = 1/2). All three share the free propagator
R = (I - h A/2)^{-1} (I + h A/2) of y' = A y + J f, A = [[0, 1], [-k, -c]], J = (0, 1) (the Green
scheme's free step equals Newmark's: module docstring of integrators.py). With Tustin's
s = (2/h)(z - 1)/(z + 1),
    (z I - R)^{-1} = 2/(h (z + 1)) (s I - A)^{-1} (I - h A/2),
and the displacement row of (s I - A)^{-1} x is ((s + c) x_1 + x_2)/(s^2 + c s + k).
  newmark: trapezoidal Newmark is the trapezoidal rule on (u, v) with the load (g^{n-1} + g^n)/2
      (its a^{n-1} carries g^{n-1}), (I - hA/2) y^n = (I + hA/2) y^{n-1} + (h/2) J (g^{n-1} + g^n), so
      Y = (z I - R)^{-1} (I - hA/2)^{-1} (h/2)(1 + z) J G = (s I - A)^{-1} J G and
      U_N = G / (s^2 + c s + k): the oscillator's transfer function at s = s(z).
  green: the load is a velocity impulse h g^n after the free step, L = h J (I - hA/2 carries
      J to (-h/2, 1 + h c/2), whose displacement row gives 1 - s h/2 = 2/(z + 1)), so
          U_G = [4 z / (z + 1)^2] U_N,     |4 z/(z + 1)^2| = 1 / cos^2(theta/2) = 1 / cos^2(pi f dt),
      real and positive: the same phase as Newmark, the amplitude times 1/cos^2(pi f dt).
  midpoint: L = h (I - hA/2)^{-1} J applied to the interval mean, so
          U_M = [2 z e^{-i theta/2} / (z + 1)] S F / (s^2 + c s + k) = U_N / cos(pi f dt).
Undamped (c = 0), s^2 = -(4/h^2) tan^2(theta/2), so with r = discrete / exact displacement:
    newmark   r = S (W^2 - theta^2) / (W^2 - 4 tan^2(theta/2))
    green     r = S (W^2 - theta^2) / (W^2 cos^2(theta/2) - 4 sin^2(theta/2))
    midpoint  r = S (W^2 - theta^2) / (cos(theta/2) (W^2 - 4 tan^2(theta/2)))
(``closed_form_ratio``). A stiff mode (W -> infinity: the mode should follow the load statically)
gets r -> S (newmark), S / cos^2(pi f dt) (green), S / cos(pi f dt) (midpoint); a free mass
(W = 0) gets S (theta/2)^2 / tan^2(theta/2) (newmark), S (theta/2)^2 / sin^2(theta/2) (green).

The cause, said precisely. Integrating the load twice into a displacement, Newmark (the trapezoidal
rule) uses two trapezoidal integrators (h/2)(z + 1)/(z - 1); the Green scheme, whose load is the
impulse train sum_k h f^k delta(t - t_k) handed to the trapezoidal free propagator, replaces them
by the two rectangle sums h z/(z - 1) and h/(z - 1): for k = 0, U_G / U_N = [2z/(z + 1)] [2/(z + 1)]
= 4 z/(z + 1)^2 exactly, and the factor is the same for every k and c. The trapezoidal sums have a
zero at z = -1 (the Nyquist frequency 1/(2 dt)); the rectangle sums do not. That zero is what the
trapezoidal rule needs: it maps every stiff mode (omega dt >> 1) to a pair of eigenvalues at
z -> -1, an undamped discrete oscillator AT the Nyquist frequency, and only the load average
(g^{n-1} + g^n)/2 (a zero there) keeps the impulses from driving it. The Green scheme's impulse
train drives it: a stiff mode's response to load content at f is multiplied by 1/cos^2(pi f dt)
(x2.0 at f dt = 1/4, x8.7 at 0.39, x41 at 0.45; with the cell-mean sampling S: x1.80, x6.69, x28.5;
midpoint S/cos: x1.27, x2.27, x4.47; newmark S: x0.90, x0.77, x0.70).
It is no error of the derivation: the scheme is second order (the factor is 1 + (pi f dt)^2 + ...),
its docstring's shifted-state argument, (I - dt/2 A)^{-2} = R + O(dt^2), holds for omega dt << 1 and
fails for the stiff modes, where the O(dt^2) term is O(omega^2 dt^2) and not small.

What would remove it without leaving the scheme: an impulse h g^n with g^n = (f^{n-1} + 2 f^n + f^{n+1})/4
(= f^n + O(h^2): second order kept) multiplies the load by (1 + z)^2/(4z) and makes the steady
displacement Newmark's exactly (``steady_ratio(..., smoothed=True)`` is ``steady_ratio('newmark', ...)``,
and the class fed that sample answers so: test_integrator_response.py). It needs the load of step
n + 1 at step n: available for a prescribed load or record (the structure alone, where
-ssi_fem_integrator newmark already is), not for the staggered coupling, whose interface force of
step n + 1 is not known then. Not implemented: the runs warn instead.

Free vibration (``free_vibration``): the eigenvalues lambda of R; spectral radius max |lambda|
and period elongation T_h / T = W / |arg lambda| of the oscillatory pair. Trapezoidal: |lambda| = 1
(undamped) and T_h / T = (W/2) / arctan(W/2), the same for all three schemes (same R).

Safe band (``safe_band``): the largest f dt below which a stiff mode's amplification stays within
1 + tol (load-sampling included): green sin(pi x)/(pi x cos^2(pi x)) <= 1.05 up to f dt = 0.0766
(15.3 Hz at dt = 5 ms); midpoint S/cos up to 0.120 (23.9 Hz); newmark S <= 1 everywhere (0.5, the Nyquist
frequency).

A record's view (``stiff_view``, ``stiff_peak_ratio``, ``record_note``). A stiff part of a structure
follows the ground rigidly; in the relative-motion form its relative displacement is the static
answer to -m a_g, so the scheme multiplies it, and the absolute acceleration of that part, by the
stiff amplification at each frequency of the record. The record filtered that way, over the record,
at its peak, is what a run overstates there: ``record_note`` warns when it exceeds 1 + SAFE_TOL and
names the step that keeps it within. (The paper building's fixed-base run under the K-NET record,
runs/integrators/fixed_base.py: predicted x1.034 at dt = 5 ms, the roof's peak absolute acceleration
green/newmark measured x1.035.) With the soil, the staggered coupling hands the soil's force to the
Green scheme as an impulse: the record is checked as a proxy for that force (the soil filters it, so
the note is conservative there); the implicit coupling solves the interface force with the soil and
is not checked (runs/integrators/coupled.py: its roof peak at 5 ms is within 2.2 % of 2.5 ms, the
staggered run's x1.41 of its own 2.5 ms run, under the record with 50-90 Hz noise).
"""
import numpy as np

SCHEMES = ("green", "newmark", "midpoint")
SAMPLING = {"green": "cell", "newmark": "cell", "midpoint": "interval"}


def _sdof_step(kind, dt, k, c, alpha=0.25, delta=0.5):
    """step(y, g) -> y^n of ``kind`` on one dof of unit mass (the classes' arithmetic, scalar)."""
    from .integrators import green_constants, d_mass_coefficient
    Dinv = 1.0 / (k + d_mass_coefficient(dt, c, alpha, delta))
    if kind == "green":
        b = green_constants(dt, c, alpha, delta)

        def step(y, g):
            u, v = y
            w = Dinv * (b["b4"] * u + b["b1"] * v)                 # predict (eq. 13)
            v1 = b["b2"] * v + b["b6"] * u + b["b7"] * w
            return np.array([b["b2"] * u + w, v1 + dt * g])      # correct: the impulse h g^n (eq. 16)
        return step, 2
    if kind == "newmark":
        a_, d_ = alpha, delta
        c_u = 1 / (a_ * dt ** 2) + c * d_ / (a_ * dt)
        c_v = 1 / (a_ * dt) + c * (d_ / a_ - 1)
        c_a = (1 / (2 * a_) - 1) + c * dt * (d_ / (2 * a_) - 1)

        def step(y, g):
            u, v, a = y
            u1 = Dinv * (c_u * u + c_v * v + c_a * a + g)
            a1 = (u1 - u - dt * v) / (a_ * dt ** 2) - (1 / (2 * a_) - 1) * a
            return np.array([u1, v + dt * ((1 - d_) * a + d_ * a1), a1])
        return step, 3
    if kind == "midpoint":
        def step(y, g):
            u, v = y
            u1 = Dinv * ((4.0 / dt ** 2 + 2.0 * c / dt) * u + 4.0 / dt * v - k * u + 2.0 * g)
            return np.array([u1, 2.0 * (u1 - u) / dt - v])
        return step, 2
    raise ValueError(f"unknown scheme {kind!r}; one of {SCHEMES}")


def step_matrices(kind, dt, k, c=0.0, alpha=0.25, delta=0.5):
    """(R, L): y^n = R y^{n-1} + L g^n for ``kind`` on one dof of unit mass, stiffness k, damping c."""
    step, n = _sdof_step(kind, dt, k, c, alpha, delta)
    R = np.column_stack([step(e, 0.0) for e in np.eye(n)])
    L = step(np.zeros(n), 1.0)
    return R, L


def sample_factor(kind, theta):
    """G / F: the load sample's amplitude for f = F e^{i Omega t}, theta = Omega dt (cell mean or
    interval mean, ``SAMPLING``)."""
    theta = np.asarray(theta, float)
    S = np.sinc(theta / (2 * np.pi))                 # numpy's sinc(x) = sin(pi x)/(pi x)
    return S * np.exp(-0.5j * theta) if SAMPLING[kind] == "interval" else S + 0j


def steady_ratio(kind, omega_dt, f_dt, zeta=0.0, alpha=0.25, delta=0.5, smoothed=False):
    """Complex steady-state displacement of ``kind`` over the exact one for a harmonic load at f dt
    on an oscillator of omega dt (mass-proportional damping ratio ``zeta`` at omega: c = 2 zeta
    omega). omega_dt = np.inf: the stiff limit (k U); omega_dt = 0 with zeta = 0: a free mass.
    ``smoothed``: the samples g^n replaced by (g^{n-1} + 2 g^n + g^{n+1})/4 (module docstring)."""
    theta = 2 * np.pi * float(f_dt)
    dt = 1.0
    if np.isinf(omega_dt):
        k = 1e8 / dt ** 2                             # stiff: r = k U_disc (exact U = F/k) to ~1e-8
        c = 0.0
    else:
        k = float(omega_dt) ** 2
        c = 2 * zeta * float(omega_dt)
    R, L = step_matrices(kind, dt, k, c, alpha, delta)
    z = np.exp(1j * theta)
    Y = np.linalg.solve(z * np.eye(len(L)) - R, z * L.astype(complex)) * sample_factor(kind, theta)
    if smoothed:
        Y = Y * (1.0 + z) ** 2 / (4.0 * z)
    exact = 1.0 / (k - theta ** 2 + 1j * c * theta)
    return Y[0] / exact


def closed_form_ratio(kind, omega_dt, f_dt):
    """Undamped, trapezoidal: r of the module docstring (real); omega_dt may be np.inf (stiff)."""
    th = 2 * np.pi * np.asarray(f_dt, float)
    S = np.sinc(th / (2 * np.pi))
    h = 0.5 * th
    if np.isinf(omega_dt):
        return {"newmark": S, "green": S / np.cos(h) ** 2, "midpoint": S / np.cos(h)}[kind]
    W2 = float(omega_dt) ** 2
    newmark = S * (W2 - th ** 2) / (W2 - 4 * np.tan(h) ** 2)
    return {"newmark": newmark, "green": S * (W2 - th ** 2) / (W2 * np.cos(h) ** 2 - 4 * np.sin(h) ** 2),
            "midpoint": newmark / np.cos(h)}[kind]


def stiff_amplification(kind, f_dt):
    """A stiff mode's steady response over its static response to a load at f dt (sampling included)."""
    return closed_form_ratio(kind, np.inf, f_dt)


def free_vibration(kind, omega_dt, zeta=0.0, alpha=0.25, delta=0.5):
    """(spectral radius, period elongation T_h/T) of ``kind`` at omega dt (eigenvalues of R)."""
    R, _ = step_matrices(kind, 1.0, float(omega_dt) ** 2, 2 * zeta * float(omega_dt), alpha, delta)
    lam = np.linalg.eigvals(R)
    lam = lam[np.abs(lam) > 1e-8 * np.abs(lam).max()]      # (newmark's third eigenvalue is 0)
    osc = lam[np.argmax(np.abs(np.angle(lam)))]
    return float(np.max(np.abs(lam))), float(omega_dt) / abs(float(np.angle(osc)))


def safe_band(kind, tol=0.05):
    """The largest f dt (<= 0.5) up to which ``stiff_amplification`` stays <= 1 + tol."""
    x = np.linspace(0.0, 0.5, 50001)[:-1]
    bad = np.nonzero(stiff_amplification(kind, x) > 1.0 + tol)[0]
    return 0.5 if not len(bad) else float(x[bad[0] - 1])


SAFE_TOL = 0.05         # the overstatement of a record's peak, as a stiff mode answers it, that is warned


def _uniform(t, a):
    """(step, samples) of acceleration samples at times t, linearly resampled at their smallest step
    if not uniform; (n,) or (n, 3)."""
    t, a = np.asarray(t, float), np.asarray(a, float)
    h = float(np.min(np.diff(t)))
    if not np.allclose(np.diff(t), h, rtol=1e-6, atol=0):
        tu = np.arange(t[0], t[-1] + 0.5 * h, h)
        a = np.stack([np.interp(tu, t, col) for col in np.atleast_2d(a.T)], axis=1).reshape((len(tu),) + a.shape[1:])
    return h, a


def stiff_view(kind, dt, t, a):
    """The record (t, a) as a stiff mode of ``kind`` at step ``dt`` answers it: each frequency f of a
    times ``stiff_amplification`` at f dt (capped at 100: the poles at f dt = 1/2 + j). A stiff part of a
    structure follows the ground rigidly, so its absolute acceleration (its share of the base shear) is
    this filtered record instead of a. Returns (step, filtered samples) on the record's (uniform) grid."""
    h, a = _uniform(t, a)
    n = a.shape[0]
    A = np.fft.rfft(a, n=2 * n, axis=0)                        # zero padding: no wrap-around
    fr = np.fft.rfftfreq(2 * n, h)
    amp = np.clip(stiff_amplification(kind, fr * dt), -100.0, 100.0)
    return h, np.fft.irfft(A * amp.reshape((-1,) + (1,) * (a.ndim - 1)), n=2 * n, axis=0)[:n]


def stiff_peak_ratio(kind, dt, t, a):
    """max |stiff_view| / max |a|: how much ``kind`` at ``dt`` overstates the record's peak where a
    structure follows it rigidly (newmark: <= 1; green: 1/cos^2(pi f dt) at the record's f)."""
    _, b = stiff_view(kind, dt, t, a)
    return float(np.abs(b).max() / np.abs(np.asarray(a, float)).max())


def record_note(kind, dt, t, a, source, axis="", tol=SAFE_TOL, advice=""):
    """A warning (str) or None: ``kind`` at step ``dt`` overstates the record's peak, as a stiff mode
    (a structure's rigid part) answers it, by more than 1 + ``tol`` (``stiff_peak_ratio``); says the
    share of the record's energy above the scheme's safe band, the overstatement, the largest dt
    (a step 0.9 times the last, down to 1e-3 of dt) that keeps it within 1 + tol, then ``advice``."""
    x = safe_band(kind, tol)
    if x >= 0.5 or not np.any(np.asarray(a, float)):          # (a record of zeros: nothing to overstate)
        return None
    ratio = stiff_peak_ratio(kind, dt, t, a)
    if ratio <= 1.0 + tol:
        return None
    h, au = _uniform(t, a)
    fr = np.fft.rfftfreq(au.shape[0], h)
    E = (np.abs(np.fft.rfft(au, axis=0)) ** 2).reshape(len(fr), -1).sum(axis=1)
    above = float(E[fr > x / dt].sum() / E.sum())
    dt_ok = next((dt * 0.9 ** k for k in range(1, 66) if stiff_peak_ratio(kind, dt * 0.9 ** k, t, a) <= 1.0 + tol),
                 None)
    name = {"green": "the Green scheme (-ssi_fem_integrator green, the staggered coupling's: the load as an "
                     "impulse h f^n at t_n)",
            "midpoint": "the implicit coupling's midpoint rule (the load as an interval mean)"}[kind]
    rule = {"green": "1/cos^2(pi f dt)", "midpoint": "1/cos(pi f dt)"}[kind]
    return (f"record '{source}'" + (f" ({axis})" if axis else "") + f": at dt = {dt:g} s {name} answers the "
            f"{100 * above:.0f} % of its acceleration's energy above {x / dt:.4g} Hz (f dt > {x:.3g}) by more than "
            f"{1 + tol:g} times a stiff mode's static response ({rule}; fem/integrator_response.py): where the "
            f"structure follows the ground rigidly it sees a peak x{ratio:.2f} the record's, so stiff modes and "
            f"absolute accelerations (on a fixed base the base shear too) are overstated"
            + (f"; -ssi_dt {dt_ok:.2g} keeps that within {100 * tol:g} %" if dt_ok else "")
            + (f"; {advice}" if advice else ""))
