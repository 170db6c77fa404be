"""Scalar time histories h(t) of loads and prescribed values, and their exact means.

One convention for the whole code (FEM and BEM), the paper's
p(t) = p0 (H(t) - H(t - t0)) (Romero, Galvin & Dominguez, Section 5.1):

  heaviside  H(t) = 1 for t > 0, 0 for t <= 0;
  box        H(t) - H(t - t0): 1 on (0, t0], 0 elsewhere;
  smoothstep (1 - cos(pi t/t0))/2 on [0, t0], then 1 (a smooth rise: petsc-ssi impedance);
  table      rows 't h' (exactly two numbers a row, t strictly increasing,
             finite): h piecewise linear between the rows, 0 before the
             first time (and for t <= 0: everything starts from rest at
             t = 0), the last value after the last time. A table whose first
             row has h != 0 at t_1 > 0 switches on with a jump at t_1.

Every history is 0 for t <= 0. Point values at a jump (t = 0, t0, t_1) are
never needed: the solvers use interval means, and those are EXACT here,
  mean(a, b) = (I(b) - I(a)) / (b - a),   I(t) = int_0^t h(s) ds,
analytic for heaviside and box and an exact trapezoid sum over the table's
breakpoints for tables (h is piecewise linear, so the trapezoid rule on its
breakpoints is exact).

The two samplings the solvers use:
  ``step_mean(m, dt)``  mean over ((m-1) dt, m dt]: the BEM's piecewise-
                        constant traction of step m (L2 projection);
  ``cell_mean(n, dt)``  mean over [t_n - dt/2, t_n + dt/2] (n = 0: [0, dt/2]):
                        the FEM's load sample at t_n (fem/integrators.py).
"""
import warnings

import numpy as np

from .petsc import SSIError

KINDS = ("heaviside", "box", "table", "smoothstep")


def read_table(table):
    """(t, h) arrays of a table file or (K, 2) array; SSIError if malformed."""
    name = f"'{table}'" if isinstance(table, str) else "(array)"
    if table is None or (isinstance(table, str) and not table.strip()):
        raise SSIError("history 'table' needs a table file of 't h' rows")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)          # an empty file: the shape check says so
            data = np.loadtxt(table, ndmin=2) if isinstance(table, str) else np.array(table, dtype=float, ndmin=2)
    except (OSError, ValueError) as exc:
        msg = str(exc).strip().splitlines()
        raise SSIError(f"history table {name}: {msg[-1] if msg else type(exc).__name__}") from None
    if data.ndim != 2 or data.shape[0] < 1 or data.shape[1] != 2:
        raise SSIError(f"history table {name}: need rows of two numbers 't h' (got shape {data.shape})")
    if not np.all(np.isfinite(data)):
        raise SSIError(f"history table {name}: non-finite value (nan or inf)")
    if np.any(np.diff(data[:, 0]) <= 0):
        k = int(np.nonzero(np.diff(data[:, 0]) <= 0)[0][0])
        raise SSIError(f"history table {name}: t must increase strictly (data row {k + 2}: t = {data[k + 1, 0]:g} "
                       f"after {data[k, 0]:g})")
    return data[:, 0].copy(), data[:, 1].copy()


class History:
    """Scalar history h(t) (module docstring) with its exact running integral.

    ``kind``: heaviside | box (needs ``t0`` > 0) | table (``table``: file
    name or (K, 2) array). Raises SSIError on a bad kind, t0 or table.
    """

    def __init__(self, kind="heaviside", t0=None, table=None):
        if kind not in KINDS:
            raise SSIError(f"unknown history '{kind}' (one of {', '.join(KINDS)})")
        self.kind = kind
        self.t0 = None if t0 is None else float(t0)
        if kind in ("box", "smoothstep") and not (self.t0 is not None and self.t0 > 0):
            raise SSIError(f"{kind} history needs a duration t0 > 0 (got {t0})")
        if kind == "table":
            self.tt, self.hh = read_table(table)
            # breakpoints of h on (0, inf): 0, the table times > 0, with h just
            # right of each (a jump from 0 to h_1 at t_1 > 0 is a breakpoint)
            knots = np.unique(np.concatenate([[0.0], self.tt[self.tt > 0]]))
            self._knots = knots
            self._h_right = self._limit(knots, right=True)
            h_left = self._limit(knots, right=False)
            self._cum = np.concatenate([[0.0], np.cumsum(0.5 * (self._h_right[:-1] + h_left[1:]) * np.diff(knots))])

    def _limit(self, t, right):
        """Table h(t+) (right) or h(t-) (left): 0 before the first time t_1."""
        t = np.asarray(t, float)
        off = (t < self.tt[0]) if right else (t <= self.tt[0])
        return np.where(off, 0.0, np.interp(t, self.tt, self.hh))

    def __call__(self, t):
        """h(t) (array in, array out)."""
        t = np.asarray(t, float)
        if self.kind == "heaviside":
            return np.where(t > 0, 1.0, 0.0)
        if self.kind == "box":
            return np.where((t > 0) & (t <= self.t0), 1.0, 0.0)
        if self.kind == "smoothstep":          # (1 - cos(pi t/t0))/2 up to t0, then 1: a broadband rise
            tc = np.clip(t, 0.0, self.t0)
            return 0.5 * (1.0 - np.cos(np.pi * tc / self.t0))
        return np.where(t > 0, np.where(t < self.tt[0], 0.0, np.interp(t, self.tt, self.hh)), 0.0)

    def integral(self, t):
        """I(t) = int_0^t h(s) ds, exact (0 for t <= 0)."""
        t = np.maximum(np.asarray(t, float), 0.0)
        if self.kind == "heaviside":
            return t
        if self.kind == "box":
            return np.minimum(t, self.t0)
        if self.kind == "smoothstep":
            tc = np.minimum(t, self.t0)
            return 0.5 * tc - self.t0 / (2 * np.pi) * np.sin(np.pi * tc / self.t0) + np.maximum(t - self.t0, 0.0)
        k = np.clip(np.searchsorted(self._knots, t, side="right") - 1, 0, len(self._knots) - 1)
        h_end = self._limit(t, right=False)
        return self._cum[k] + 0.5 * (self._h_right[k] + h_end) * (t - self._knots[k])

    def mean(self, a, b):
        """Exact mean of h over (a, b), b > a."""
        if not b > a:
            raise ValueError(f"mean over ({a}, {b}): need b > a")
        return float((self.integral(b) - self.integral(a)) / (b - a))

    def step_mean(self, m, dt):
        """Mean over ((m-1) dt, m dt] (BEM, piecewise-constant tractions)."""
        return self.mean((m - 1) * dt, m * dt)

    def cell_mean(self, n, dt):
        """Mean over [t_n - dt/2, t_n + dt/2], for n = 0 over [0, dt/2] (FEM load sample)."""
        return self.mean(max(0.0, (n - 0.5) * dt), (n + 0.5) * dt)
