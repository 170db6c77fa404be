"""The one time grid of every driver (BEM, FEM, coupled).

A run of end time t_end with step dt takes

    n_steps = ceil(t_end / dt - 1e-9)

steps, at t_n = n dt, n = 1..n_steps: the run covers [0, t_end] (its last time
is the first grid time >= t_end), and a t_end that is a whole number of steps
up to round-off (t_end / dt within 1e-9 of an integer) takes exactly that
number. (Before this rule the BEM took ceil(t_end/dt) and the FEM
round(t_end/dt) steps: t_end = 0.04 s, dt = 7.5e-4 s gave 54 and 53.)
"""
import math


def n_steps(t_end, dt):
    """Number of steps of a run to ``t_end`` with step ``dt`` (see the module docstring)."""
    return max(int(math.ceil(t_end / dt - 1e-9)), 0)
