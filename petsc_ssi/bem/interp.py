r"""Interpolation of the lag matrices beyond a threshold time (paper eqs. 8-12;
method notes section 3).

Lag time of lag l (l = n - m + 1): tau_l = (l - 1) dt. Lags with tau_l < T_L
are stored exactly; lags with T_L <= tau_l <= T_N are combinations of k
matrices H(T_j), G(T_j) computed exactly at the interpolation times T_j:

  H_l ~ sum_j I(l, j) H(T_j).

Chebyshev-Lagrange (eqs. 9, 11): T_j = [(T_N - T_L) cos((2j-1) pi / 2k)
+ (T_N + T_L)] / 2, I(l, j) = prod_{i != j} (tau_l - T_i) / (T_j - T_i).
Multi-linear (eqs. 10, 12): T_j = T_L + (T_N - T_L) ((j-1)/(k-1))^p, hat
weights. Eq. 12 prints the exponent as k^p; we read it as a grading
exponent p (``-ssi_interp_grading``, p = 1: equal spacing; p > 1 clusters the
nodes near T_L, where the matrices change fastest).

T_N is the last lag time that can be non-zero (r_max / c_s + dt) or the last
lag a run of n steps uses, whichever is smaller: the interpolation covers no
more than the run needs. Lags beyond T_N are exactly zero (truncation).
"""
import math

import numpy as np

from ..petsc import SSIError


def nodes(method, TL, TN, k, grading=1.0):
    if method == "chebyshev":
        j = np.arange(1, k + 1)
        return 0.5 * ((TN - TL) * np.cos((2 * j - 1) * np.pi / (2 * k)) + (TN + TL))
    if method == "linear":
        if k < 2:
            raise SSIError("-ssi_interp linear needs -ssi_interp_k >= 2")
        return TL + (TN - TL) * (np.arange(k) / (k - 1.0)) ** grading
    raise SSIError(f"unknown interpolation '{method}'")


def weights(method, T, tau):
    """I[l, j]: weight of node j at lag times tau (array). (len(tau), k)."""
    T = np.asarray(T, float)
    tau = np.asarray(tau, float)
    k = len(T)
    W = np.zeros((len(tau), k))
    if method == "chebyshev":
        for j in range(k):
            w = np.ones_like(tau)
            for i in range(k):
                if i != j:
                    w *= (tau - T[i]) / (T[j] - T[i])
            W[:, j] = w
        return W
    # multi-linear: hat functions on the sorted nodes
    order = np.argsort(T)
    Ts = T[order]
    idx = np.clip(np.searchsorted(Ts, tau, side="right") - 1, 0, k - 2)
    a, b = Ts[idx], Ts[idx + 1]
    th = np.clip((tau - a) / (b - a), 0.0, 1.0)
    rows = np.arange(len(tau))
    W[rows, order[idx]] = 1.0 - th
    W[rows, order[idx + 1]] += th
    return W


class Plan:
    """Which lags are exact, which interpolated, and from which nodes."""

    def __init__(self, method, dt, L, TL, k, grading=1.0):
        self.method = method
        self.dt = dt
        self.L = L                              # last lag the run uses (and can be non-zero)
        self.TN = (L - 1) * dt                  # lag time of lag L
        self.TL = TL
        self.k = k
        if method == "none" or TL is None or TL >= self.TN or k < 1:
            self.active = False
            self.Lx = L
            self.T = np.zeros(0)
            self.W = np.zeros((0, 0))
            return
        Lx = int(math.ceil(TL / dt - 1e-9))    # exact: (l - 1) dt < T_L
        self.Lx = max(Lx, 2)                    # lags 1 and 2 form the step matrix
        if self.Lx >= L:
            self.active = False
            self.Lx = L
            self.T = np.zeros(0)
            self.W = np.zeros((0, 0))
            return
        self.active = True
        self.T = nodes(method, TL, self.TN, k, grading)
        tau = (np.arange(self.Lx + 1, L + 1) - 1) * dt
        self.W = weights(method, self.T, tau)   # row l - Lx - 1

    def describe(self):
        if not self.active:
            return f"lag interpolation: none ({self.L} exact lags)"
        return (f"lag interpolation: {self.method}, T_L = {self.TL:.5g} s ({self.Lx} exact lags), "
                f"k = {self.k} matrices at T_j in [{self.T.min():.5g}, {self.T.max():.5g}] s, "
                f"replacing lags {self.Lx + 1}..{self.L} (the last at {self.TN:.5g} s: T_N or the run's end, the sooner)")

    def kernel_time(self, j):
        """(lag l, offset) with kernel time T_j + dt = l dt + offset."""
        t = self.T[j] + self.dt
        l = int(math.floor(t / self.dt + 1e-12))
        return l, max(0.0, t - l * self.dt)


def state_weights(plan, n, stabilized=True):
    """coef[m, i]: the weight of state m in the interpolated history w_i = sum_l I(l, i) q_l(u) of step n
    (q_l the scheme's states of lag l: ``march``), (n + 1, k); None: no interpolated lag reaches a state
    yet."""
    lags = np.arange(plan.Lx + 1, min(plan.L, n + 1) + 1)
    if lags.size == 0:
        return None
    offs = ((2, 1.0), (1, 2.0), (0, 1.0)) if stabilized else ((1, 1.0),)
    coef = np.zeros((n + 1, plan.k))      # coef[m, i]: weight of state m in w_i
    for off, c in offs:
        m = n - lags + off
        ok = (m >= 1) & (m <= n - 1)
        np.add.at(coef, m[ok], c * plan.W[lags[ok] - plan.Lx - 1])
    return coef


def auto(cs, dt, L, receivers, source, tau_l=1.5, steps_per_matrix=5):
    """The paper's rule: tau_L = c_s T_L / r above the Rayleigh arrival (1.5)
    for the farthest receiver of interest, one exact matrix every 5 steps.
    Returns (T_L, k, reason)."""
    TN = (L - 1) * dt
    if len(receivers) == 0:
        return None, 0, "no receivers: nothing to protect, but no interpolation without a receiver to choose T_L"
    r = float(np.max(np.linalg.norm(np.asarray(receivers)[:, :2] - np.asarray(source)[:2], axis=1)))
    TL = tau_l * r / cs
    if TL >= TN:
        return None, 0, (f"T_L = {tau_l} r/c_s = {TL:.4g} s for r = {r:.4g} m is beyond the last lag, at {TN:.4g} s "
                         "(T_N or the run's end, the sooner): all lags exact")
    k = max(2, int(math.ceil((TN - TL) / (steps_per_matrix * dt))))
    return TL, k, (f"tau_L = {tau_l} (above the Rayleigh arrival 1.09) at the farthest receiver "
                   f"r = {r:.4g} m gives T_L = {TL:.4g} s; one exact matrix every {steps_per_matrix} "
                   f"steps over [T_L, {TN:.4g} s] (to the last lag: T_N or the run's end, the sooner) gives k = {k}")
