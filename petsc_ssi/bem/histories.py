"""Time histories of loads and prescribed values, sampled on the time bases.

Tractions are piecewise constant: p^m is the MEAN of f over ((m-1)dt, m dt]
(the L2 projection onto the basis). Displacements are piecewise linear:
u^m = f(m dt) (nodal interpolation).
"""
import numpy as np

from ..petsc import SSIError


def make(kind, t0=None, table=None):
    if kind == "heaviside":
        return lambda t: (np.asarray(t) > 0).astype(float)
    if kind == "box":
        return lambda t: ((np.asarray(t) > 0) & (np.asarray(t) <= t0)).astype(float)
    if kind == "table":
        try:
            data = np.loadtxt(table, ndmin=2)
        except (OSError, ValueError) as exc:
            raise SSIError(f"history table '{table}': {exc}") from None
        if data.shape[1] < 2 or np.any(np.diff(data[:, 0]) <= 0):
            raise SSIError(f"history table '{table}': need rows 't value' with increasing t")
        return lambda t: np.interp(t, data[:, 0], data[:, 1], left=0.0, right=data[-1, 1])
    raise SSIError(f"unknown history '{kind}'")


def step_mean(f, m, dt, kind=None, t0=None, sub=64):
    """Mean of f over ((m-1) dt, m dt]; exact for heaviside and box."""
    a, b = (m - 1) * dt, m * dt
    if kind == "heaviside":
        return 1.0
    if kind == "box":
        return float(np.clip((min(b, t0) - a) / dt, 0.0, 1.0))
    s = np.linspace(a, b, sub + 1)
    s = 0.5 * (s[1:] + s[:-1])
    return float(np.mean(f(s)))
