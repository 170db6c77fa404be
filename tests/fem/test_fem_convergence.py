"""Forced responses converge to the exact solution at order 2 (SDOF and a 3-dof chain).

Exact solutions: the first-order system y' = A y + b h(t), y = (u, v), is
augmented with the load as extra states (a constant c' = 0 for the step and
the box, an oscillator for the sine) and propagated with expm, switching the
box off at t0 (which lies inside a time step for every dt used).

Load samples follow loads.py / integrators.py: f^n is the mean of f over
[t_n - dt/2, t_n + dt/2] and the Green integrator starts with the half
impulse of [0, dt/2]. The last test shows what the naive sampling
f^n = f(t_n), without the initial half impulse, costs: order 1.

At the one node next to a jump of the load (the end of the box) the velocity
has an O(dt) local error, for both integrators: a nodal load sample cannot
say where inside the step the load stops (the output velocity holds half of
the impulse of that step). The displacement stays second order everywhere;
the velocity is checked for order 2 away from t0, and its local error at the
jump against the bound |F| dt / m.
"""
import numpy as np
import pytest
from scipy.linalg import expm

from fem_helpers import chain_mats, vec_from
from petsc_ssi.fem.integrators import GreenIntegrator, NewmarkIntegrator
from petsc_ssi.fem.loads import History

pytestmark = pytest.mark.unit

NS = (60, 120, 240, 480)        # steps over the interval T
ORDER_TOL = 0.2                 # observed order must be 2 +- 0.2


class Sine:
    kind = "sine"

    def __init__(self, w):
        self.w = w

    def cell_mean(self, n, dt):
        a, b = max(0.0, (n - 0.5) * dt), (n + 0.5) * dt
        return (np.cos(self.w * a) - np.cos(self.w * b)) / (self.w * (b - a))

    def __call__(self, t):
        return np.sin(self.w * t)


def exact(Kd, md, am, F, load, T, N):
    """u(t_n), v(t_n), n = 0..N, of M a + am M v + K u = F h(t), zero initial state."""
    n = len(md)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -Kd / md[:, None]
    A[n:, n:] = -am * np.eye(n)
    b = np.concatenate([np.zeros(n), F / md])
    if isinstance(load, Sine):
        Aa = np.zeros((2 * n + 2, 2 * n + 2))
        Aa[:2 * n, :2 * n], Aa[:2 * n, 2 * n] = A, b
        Aa[2 * n, 2 * n + 1], Aa[2 * n + 1, 2 * n] = load.w, -load.w      # (sin, cos)' = w (cos, -sin)
        z0 = np.r_[np.zeros(2 * n), 0.0, 1.0]
    else:
        Aa = np.zeros((2 * n + 1, 2 * n + 1))
        Aa[:2 * n, :2 * n], Aa[:2 * n, 2 * n] = A, b
        z0 = np.r_[np.zeros(2 * n), 1.0]
    t = np.linspace(0, T, N + 1)
    out = np.empty((N + 1, len(z0)))
    for i, ti in enumerate(t):
        if load.kind == "box" and ti > load.t0:
            z1 = expm(Aa * load.t0) @ z0
            z1[-1] = 0.0
            out[i] = expm(Aa * (ti - load.t0)) @ z1
        else:
            out[i] = expm(Aa * ti) @ z0
    return out[:, :n], out[:, n:2 * n]


def simulate(cls, Kd, md, am, F, load, T, N, naive=False):
    K, m = chain_mats(Kd, md)
    dt = T / N
    integ = cls(K, m, dt, am, prefix="tconv_")
    f = lambda s: vec_from(s * F, m)      # noqa: E731
    integ.start(f0=None if naive else f(load.cell_mean(0, dt)))
    us, vs = [integ.u.getArray().copy()], [integ.velocity().getArray().copy()]
    for n in range(1, N + 1):
        integ.step(f(float(load(n * dt)) if naive else load.cell_mean(n, dt)))
        us.append(integ.u.getArray().copy())
        vs.append(integ.velocity().getArray().copy())
    integ.destroy()
    return np.array(us), np.array(vs)


def observed_order(cls, Kd, md, am, F, load, T, naive=False):
    """Orders of the max-in-time errors of u and v (v: away from a jump) and the errors."""
    eu, ev, ejump = [], [], []
    for N in NS:
        ue, ve = exact(Kd, md, am, F, load, T, N)
        u, v = simulate(cls, Kd, md, am, F, load, T, N, naive)
        t = np.linspace(0, T, N + 1)
        near = np.abs(t - getattr(load, "t0", -1.0)) < T / N if load.kind == "box" else np.zeros(N + 1, bool)
        eu.append(np.abs(u - ue).max() / np.abs(ue).max())
        ev.append(np.abs(v - ve)[~near].max() / np.abs(ve).max())
        ejump.append(np.abs(v - ve)[near].max(initial=0.0) / (np.abs(F / md).max() * T / N))
    h = np.log(np.asarray(NS, float))
    return -np.polyfit(h, np.log(eu), 1)[0], -np.polyfit(h, np.log(ev), 1)[0], eu, max(ejump)


SDOF = (np.array([[(2 * np.pi) ** 2]]), np.array([1.0]), 0.5, np.array([1.0]))
CHAIN = (np.array([[30.0, -20.0, 0.0], [-20.0, 35.0, -15.0], [0.0, -15.0, 15.0]]), np.array([1.0, 2.0, 1.5]),
         0.3, np.array([0.0, 0.0, 1.0]))
LOADS = {"heaviside": History("heaviside"), "box": History("box", 0.537), "sine": Sine(5.0)}


@pytest.mark.parametrize("system", ["sdof", "chain"])
@pytest.mark.parametrize("load", ["heaviside", "box", "sine"])
@pytest.mark.parametrize("cls", [GreenIntegrator, NewmarkIntegrator])
def test_order_two(PETSc, cls, load, system):
    """Displacement and velocity errors (max over [0, T], relative) fall as dt^2 (order 2 +- 0.2)."""
    Kd, md, am, F = SDOF if system == "sdof" else CHAIN
    pu, pv, eu, ejump = observed_order(cls, Kd, md, am, F, LOADS[load], 2.0)
    assert abs(pu - 2) < ORDER_TOL, (pu, eu)
    assert abs(pv - 2) < ORDER_TOL, pv
    assert eu[-1] < 2e-3            # and small in absolute terms on the finest grid
    assert ejump <= 1.0             # velocity next to the end of the box: within |F| dt / m


def test_naive_sampling_is_first_order(PETSc):
    """f^n = f(t_n) and no half impulse at t = 0: the impulse train is a right-rectangle rule of the
    Duhamel integral, off by dt/2 G(t) f(0): displacement order 1 (1 +- 0.2)."""
    Kd, md, am, F = SDOF
    pu, _, eu, _ = observed_order(GreenIntegrator, Kd, md, am, F, LOADS["heaviside"], 2.0, naive=True)
    assert abs(pu - 1) < ORDER_TOL, (pu, eu)


def interface_run(Kd, md, am, F, load, T, N, extrapolate):
    """Green run whose whole load enters as the interface force of correct(): the BE-like traction
    p^n = mean of f over ((n-1) dt, n dt], handed over as it is or extrapolated 1.5 p^n - 0.5 p^{n-1}."""
    K, m = chain_mats(Kd, md)
    dt = T / N
    integ = GreenIntegrator(K, m, dt, am, prefix="tconv_if_")
    integ.start()                                   # at rest, p^0 = 0
    p_prev, us = 0.0, [integ.u.getArray().copy()]
    for n in range(1, N + 1):
        p = (np.cos(load.w * (n - 1) * dt) - np.cos(load.w * n * dt)) / (load.w * dt)    # step mean
        integ.predict()
        integ.correct(f_interface=vec_from((1.5 * p - 0.5 * p_prev if extrapolate else p) * F, m))
        us.append(integ.u.getArray().copy())
        p_prev = p
    integ.destroy()
    return np.array(us)


def test_interface_traction_must_be_extrapolated(PETSc):
    """The coupling note of integrators.py, on the SDOF under f = sin(5 t) (T = 2 s): an interface
    force piecewise constant on (t_{n-1}, t_n] handed to correct() as it is gives displacement order
    1 (1 +- 0.2); extrapolated to the cell [t_n - dt/2, t_n + dt/2] as 1.5 p^n - 0.5 p^{n-1} it gives
    order 2 (2 +- 0.2) and a 20x smaller error on the finest grid (measured: 1.07, 2.02, 28x)."""
    Kd, md, am, F = SDOF
    load, T = Sine(5.0), 2.0
    orders, finest = {}, {}
    for extrapolate in (False, True):
        eu = []
        for N in NS:
            ue, _ = exact(Kd, md, am, F, load, T, N)
            u = interface_run(Kd, md, am, F, load, T, N, extrapolate)
            eu.append(np.abs(u - ue).max() / np.abs(ue).max())
        orders[extrapolate] = -np.polyfit(np.log(np.asarray(NS, float)), np.log(eu), 1)[0]
        finest[extrapolate] = eu[-1]
    assert abs(orders[False] - 1) < ORDER_TOL, orders
    assert abs(orders[True] - 2) < ORDER_TOL, orders
    assert finest[True] < finest[False] / 20, finest
