"""Slow, obvious reference implementations used only by the tests.

- ``f1_numeric``: the Heaviside response by numerical time integration of the
  impulse response's regular part plus the delta terms (Aki & Richards 4.23).
- ``t2_numeric``: the traction of F2 by central finite differences of F2 in
  space (F2 itself from the closed form in numpy, written independently).
"""
import numpy as np


def _f2_closed(x, t, alpha, beta, rho):
    r = np.linalg.norm(x)
    g = x / r
    a, b = r / alpha, r / beta
    if t <= a:
        q2 = 0.0
    elif t <= b:
        q2 = 0.5 * ((t ** 3 - a ** 3) / 3 - a * a * (t - a))
    else:
        q2 = 0.5 * ((b ** 3 - a ** 3) / 3 - a * a * (b - a)) + 0.5 * (b * b - a * a) * (t - b)
    ramp = lambda s: max(s, 0.0)
    G = np.outer(g, g)
    I = np.eye(3)
    return ((3 * G - I) / r ** 3 * q2 + G / (alpha ** 2 * r) * ramp(t - a)
            - (G - I) / (beta ** 2 * r) * ramp(t - b)) / (4 * np.pi * rho)


def f1_numeric(x, t, alpha, beta, rho, n=4001):
    """Heaviside response by quadrature of t*W(t) plus the delta steps."""
    r = np.linalg.norm(x)
    g = x / r
    a, b = r / alpha, r / beta
    G = np.outer(g, g)
    I = np.eye(3)
    if t <= a:
        return np.zeros((3, 3))
    s = np.linspace(a, min(t, b), n)
    q = np.trapz(s, s)
    out = (3 * G - I) / r ** 3 * q + G / (alpha ** 2 * r)
    if t > b:
        out -= (G - I) / (beta ** 2 * r)
    return out / (4 * np.pi * rho)


def t2_numeric(x, nvec, t, alpha, beta, rho, h=1e-6):
    """Traction of F2 at field point x (source at origin), finite differences."""
    cp2 = rho * alpha ** 2
    mu = rho * beta ** 2
    lam = cp2 - 2 * mu
    grad = np.zeros((3, 3, 3))  # [l, i, j] = d F2_{li} / d x_j
    for j in range(3):
        e = np.zeros(3)
        e[j] = h * max(1.0, np.linalg.norm(x))
        grad[:, :, j] = (_f2_closed(x + e, t, alpha, beta, rho)
                         - _f2_closed(x - e, t, alpha, beta, rho)) / (2 * e[j])
    out = np.zeros((3, 3))
    for l in range(3):
        eps = grad[l]
        div = np.trace(eps)
        sig = lam * div * np.eye(3) + mu * (eps + eps.T)
        out[l] = sig @ nvec
    return out
