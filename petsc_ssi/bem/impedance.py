"""Impedance functions from time-domain runs: the spectrum of a resultant's response to a
smooth-step motion and the rigid-body fit of a footing's motion (``petsc-ssi impedance``,
``app/impedance.py``, runs one prescribed-motion run per mode and uses these)."""
import math

import numpy as np


def step_spectrum(s, dt, traction=False, pad=8):
    """(omega, S(omega)): the FFT of the first differences of a series s_n, n = 1..K, that starts
    from rest and settles (s_0 = 0), zero-padded to ``pad`` times the next power of two. A traction
    resultant (``traction``: the mean over (t_{n-1}, t_n]) is moved by half a step to t_n, where
    displacements are sampled: times exp(i omega dt/2)."""
    s = np.asarray(s, dtype=float)
    n = pad * (1 << int(math.ceil(math.log2(max(len(s), 2)))))
    om = 2 * np.pi * np.fft.rfftfreq(n, dt)
    S = np.fft.rfft(np.diff(np.r_[0.0, s], axis=0), n, axis=0)
    if traction:
        S = S * np.exp(1j * om * dt / 2).reshape((-1,) + (1,) * (S.ndim - 1))
    return om, S


def spectrum(R, h, dt, pad=8):
    """(omega, K(omega)) from the resultant R_n and the motion factor h_n, n = 1..K (module docstring)."""
    om, SR = step_spectrum(R, dt, traction=True, pad=pad)
    return om, SR / step_spectrum(h, dt, pad=pad)[1]


def rigid_fit(x, u, x_ref=(0.0, 0.0, 0.0)):
    """Least-squares rigid motion of nodal displacements: u_i ~ t + theta x (x_i - x_ref).

    x (n, 3) node positions, u (..., n, 3) displacements (any leading axes, e.g. steps). Returns
    (t (..., 3), theta (..., 3), residual): the translation, the small rotation about x_ref and
    max |u - fit| / max |u| (how rigid the motion is). For a foundation that is not rigid (a
    flexible block, a slab) this is the rigid-body part of its interface motion."""
    r = np.asarray(x, dtype=float) - np.asarray(x_ref, dtype=float)
    u = np.asarray(u, dtype=float)
    n = len(r)
    A = np.zeros((n, 3, 6))
    A[:, :, :3] = np.eye(3)
    A[:, 0, 4], A[:, 0, 5] = r[:, 2], -r[:, 1]      # theta x r = (th_y r_z - th_z r_y, ...)
    A[:, 1, 3], A[:, 1, 5] = -r[:, 2], r[:, 0]
    A[:, 2, 3], A[:, 2, 4] = r[:, 1], -r[:, 0]
    A = A.reshape(3 * n, 6)
    lead = u.shape[:-2]
    b = u.reshape(-1, 3 * n).T
    sol, *_ = np.linalg.lstsq(A, b, rcond=None)
    fit = (A @ sol).T.reshape(u.shape)
    scale = np.abs(u).max()
    resid = float(np.abs(u - fit).max() / scale) if scale > 0 else 0.0
    sol = sol.T.reshape(lead + (6,))
    return sol[..., :3], sol[..., 3:], resid
