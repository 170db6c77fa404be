r"""Time-integrated 3D elastodynamic (Stokes) kernels, paper eqs. 1-5.

The full-space displacement response to an impulsive point force (Aki &
Richards eq. 4.23; Dominguez 1993), with r = |x - xi|, gamma = (x - xi)/r,
alpha = c_p, beta = c_s:

  u_lk(t) = 1/(4 pi rho) [ (3 g_l g_k - d_lk)/r^3 t W(t)
                           + g_l g_k/(alpha^2 r) delta(t - r/alpha)
                           - (g_l g_k - d_lk)/(beta^2 r) delta(t - r/beta) ],
  W(t) = H(t - r/alpha) - H(t - r/beta).

Time basis (method notes, section 1): tractions piecewise constant
(mu^m = 1 on ((m-1)dt, m dt]), displacements piecewise linear (hat eta^m
centred at m dt). With the lag index l = n - m + 1 the time integrals are
closed-form differences of the once and twice time-integrated kernels

  F1(t) = int_0^t u ds  (Heaviside response),   F2(t) = int_0^t F1 ds,
  U^l = F1(l dt) - F1((l-1) dt),
  P^l = [T2(l dt) - 2 T2((l-1) dt) + T2((l-2) dt)] / dt,   T2 = traction of F2,

because the hat is the second difference of a ramp. Both are continuous
functions of the lag time T = l dt, which defines a lag matrix at a
non-integer lag (needed by the interpolation of paper eqs. 8-12).

Both F1 and F2 have the isotropic form A(r,t) d_lk + B(r,t) g_l g_k with
(a = r/alpha, b = r/beta, 4 pi rho factored out)

  F1: Q  = (min(t,b)^2 - a^2)/2 for t > a, else 0
      A1 = -Q/r^3 + H(t-b)/(beta^2 r),   B1 = 3Q/r^3 + H(t-a)/(alpha^2 r) - H(t-b)/(beta^2 r)
  F2: Q2 = [(t^3-a^3)/3 - a^2 (t-a)]/2                    for a < t <= b
         = (a^3 - b^3)/3 + (b^2 - a^2) t/2                 for t > b
      A2 = -Q2/r^3 + (t-b)_+/(beta^2 r),  B2 = 3Q2/r^3 + (t-a)_+/(alpha^2 r) - (t-b)_+/(beta^2 r)

and the traction (direction k, at x with normal n, load direction l) of a
field A d_lk + B g_l g_k is, with gn = g.n and ' = d/dr at fixed t,

  p_lk = lam (A' + B' + 2B/r) g_l n_k
       + mu [ A' (gn d_lk + g_k n_l) + 2 B' gn g_l g_k
              + (B/r)(n_l g_k + 2 g_l n_k + d_lk gn - 4 g_l g_k gn) ].

For t -> infinity F1 is Kelvin's static solution and P summed over all lags
is Kelvin's static traction kernel (tests check both to round-off). For
r < beta*dt, U^1 and P^1 ARE the static kernels (all waves have passed), so
the singular integrals of lag 1 are the static ones (see ``quadrature``).
"""
import math

import numpy as np
from numba import njit

FOUR_PI = 4.0 * math.pi


@njit(cache=True, fastmath=False)
def ab1(r, t, alpha, beta):
    """A, B of the Heaviside response F1 (times 4 pi rho)."""
    a = r / alpha
    b = r / beta
    if t <= a:
        return 0.0, 0.0
    tm = t if t < b else b
    q = 0.5 * (tm * tm - a * a)
    r3 = r * r * r
    A = -q / r3
    B = 3.0 * q / r3 + 1.0 / (alpha * alpha * r)
    if t > b:
        A += 1.0 / (beta * beta * r)
        B -= 1.0 / (beta * beta * r)
    return A, B


@njit(cache=True, fastmath=False)
def ab2(r, t, alpha, beta):
    """A, B, dA/dr, dB/dr of the twice-integrated response F2 (times 4 pi rho)."""
    a = r / alpha
    b = r / beta
    if t <= a:
        return 0.0, 0.0, 0.0, 0.0
    r2 = r * r
    r3 = r2 * r
    if t <= b:
        q2r3 = 0.5 * ((t * t * t - a * a * a) / 3.0 - a * a * (t - a)) / r3
        dq2 = -a * (t - a) / alpha
    else:
        q2r3 = (1.0 / (alpha ** 3) - 1.0 / (beta ** 3)) / 3.0 + 0.5 * (1.0 / (beta * beta) - 1.0 / (alpha * alpha)) * t / r
        dq2 = b * (t - b) / beta - a * (t - a) / alpha
    dq2r3 = dq2 / r3 - 3.0 * q2r3 / r
    ia2 = 1.0 / (alpha * alpha)
    ib2 = 1.0 / (beta * beta)
    A = -q2r3
    dA = -dq2r3
    B = 3.0 * q2r3 + (t - a) * ia2 / r
    dB = 3.0 * dq2r3 - ia2 / (alpha * r) - (t - a) * ia2 / r2
    if t > b:
        A += (t - b) * ib2 / r
        dA += -ib2 / (beta * r) - (t - b) * ib2 / r2
        B -= (t - b) * ib2 / r
        dB -= -ib2 / (beta * r) - (t - b) * ib2 / r2
    return A, B, dA, dB


@njit(cache=True, inline="always")
def ab2_fast(r, ir, t, ia, ib):
    """ab2 with reciprocals precomputed (ir = 1/r, ia = 1/alpha, ib = 1/beta):
    the same values as ``ab2`` up to round-off, no divisions or powers."""
    a = r * ia
    b = r * ib
    if t <= a:
        return 0.0, 0.0, 0.0, 0.0
    ir2 = ir * ir
    ir3 = ir2 * ir
    ia2 = ia * ia
    ib2 = ib * ib
    if t <= b:
        q2r3 = 0.5 * ((t * t * t - a * a * a) * (1.0 / 3.0) - a * a * (t - a)) * ir3
        dq2 = -a * (t - a) * ia
    else:
        q2r3 = (ia2 * ia - ib2 * ib) * (1.0 / 3.0) + 0.5 * (ib2 - ia2) * t * ir
        dq2 = b * (t - b) * ib - a * (t - a) * ia
    dq2r3 = dq2 * ir3 - 3.0 * q2r3 * ir
    A = -q2r3
    dA = -dq2r3
    B = 3.0 * q2r3 + (t - a) * ia2 * ir
    dB = 3.0 * dq2r3 - ia2 * ia * ir - (t - a) * ia2 * ir2
    if t > b:
        e = ib2 * ib * ir + (t - b) * ib2 * ir2
        f = (t - b) * ib2 * ir
        A += f
        dA -= e
        B -= f
        dB += e
    return A, B, dA, dB


@njit(cache=True, fastmath=False)
def traction_from_ab(g, n, r, A, B, dA, dB, lam, mu, out):
    """out[l,k] = traction (direction k, normal n) of A d_lk + B g_l g_k."""
    gn = g[0] * n[0] + g[1] * n[1] + g[2] * n[2]
    c1 = lam * (dA + dB + 2.0 * B / r)
    br = B / r
    for l in range(3):
        for k in range(3):
            v = c1 * g[l] * n[k]
            v += mu * (dA * (g[k] * n[l]) + 2.0 * dB * gn * g[l] * g[k]
                       + br * (n[l] * g[k] + 2.0 * g[l] * n[k] - 4.0 * g[l] * g[k] * gn))
            if l == k:
                v += mu * (dA + br) * gn
            out[l, k] = v


@njit(cache=True, fastmath=False)
def f1_tensor(g, r, t, alpha, beta, rho, out):
    """out[l,k] = F1_lk(r, t): displacement response to a Heaviside point force."""
    A, B = ab1(r, t, alpha, beta)
    s = 1.0 / (FOUR_PI * rho)
    for l in range(3):
        for k in range(3):
            out[l, k] = s * B * g[l] * g[k]
        out[l, l] += s * A


@njit(cache=True, fastmath=False)
def t2_tensor(g, n, r, t, alpha, beta, rho, out):
    """out[l,k] = traction of F2 (twice time-integrated displacement kernel)."""
    A, B, dA, dB = ab2(r, t, alpha, beta)
    mu = rho * beta * beta
    lam = rho * alpha * alpha - 2.0 * mu
    s = 1.0 / (FOUR_PI * rho)
    traction_from_ab(g, n, r, s * A, s * B, s * dA, s * dB, lam, mu, out)


@njit(cache=True, fastmath=False)
def kelvin_u(g, r, nu, mu, out):
    """Static Kelvin displacement kernel."""
    c = 1.0 / (16.0 * math.pi * mu * (1.0 - nu) * r)
    for l in range(3):
        for k in range(3):
            out[l, k] = c * g[l] * g[k]
        out[l, l] += c * (3.0 - 4.0 * nu)


@njit(cache=True, fastmath=False)
def kelvin_p(g, n, r, nu, out):
    """Static Kelvin traction kernel (textbook form, independent of ab2)."""
    c = -1.0 / (8.0 * math.pi * (1.0 - nu) * r * r)
    gn = g[0] * n[0] + g[1] * n[1] + g[2] * n[2]
    for l in range(3):
        for k in range(3):
            v = gn * 3.0 * g[l] * g[k] - (1.0 - 2.0 * nu) * (g[l] * n[k] - g[k] * n[l])
            if l == k:
                v += gn * (1.0 - 2.0 * nu)
            out[l, k] = c * v


def lag_u(rvec, T, dt, alpha, beta, rho):
    """U at lag time T (T = l dt for lag l): F1(T) - F1(T - dt). Slow helper."""
    r = float(np.linalg.norm(rvec))
    g = np.asarray(rvec, float) / r
    a = np.zeros((3, 3))
    b = np.zeros((3, 3))
    f1_tensor(g, r, T, alpha, beta, rho, a)
    if T - dt > 0:
        f1_tensor(g, r, T - dt, alpha, beta, rho, b)
    return a - b


def lag_p(rvec, n, T, dt, alpha, beta, rho):
    """P at lag time T: [T2(T) - 2 T2(T - dt) + T2(T - 2dt)]/dt. Slow helper."""
    r = float(np.linalg.norm(rvec))
    g = np.asarray(rvec, float) / r
    n = np.asarray(n, float)
    out = np.zeros((3, 3))
    w = (1.0, -2.0, 1.0)
    for i in range(3):
        t = T - i * dt
        if t > 0:
            tmp = np.zeros((3, 3))
            t2_tensor(g, n, r, t, alpha, beta, rho, tmp)
            out += w[i] * tmp
    return out / dt
