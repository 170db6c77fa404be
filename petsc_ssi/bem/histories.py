"""Time histories of loads and prescribed values, sampled on the BEM time bases.

A thin layer over ``petsc_ssi.histories`` (one convention for FEM and BEM:
heaviside H(t) = 1 for t > 0, box 1 on (0, t0], tables 0 before their first
time; see there). Tractions are piecewise constant: p^m is the MEAN of f over
((m-1)dt, m dt] (the L2 projection onto the basis), exact for every kind.
Displacements are piecewise linear: u^m = f(m dt) (nodal interpolation).
"""
import numpy as np

from ..histories import History


def make(kind, t0=None, table=None):
    """The history h(t) of ``kind`` (a callable ``History``); SSIError if bad."""
    return History(kind, t0, table)


def step_mean(f, m, dt, kind=None, t0=None, sub=64):
    """Mean of f over ((m-1) dt, m dt].

    Exact for a ``History`` (what ``make`` returns) and for kind heaviside/box;
    any other callable gets a ``sub``-point midpoint rule.
    """
    if kind in ("heaviside", "box"):
        return History(kind, t0).step_mean(m, dt)
    if isinstance(f, History):
        return f.step_mean(m, dt)
    a, b = (m - 1) * dt, m * dt
    s = np.linspace(a, b, sub + 1)
    s = 0.5 * (s[1:] + s[:-1])
    return float(np.mean(f(s)))
