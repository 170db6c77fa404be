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


class TimeGrid:
    """The time grid of a run, made once by its problem: step ``dt``, ``n_steps`` (the rule above),
    times t_n = n dt, and which steps write fields (every ``stride`` steps; 0: none). Everything
    that needs a step's time, or a time's step, asks the grid: no ``round(t / dt)``."""

    def __init__(self, dt, t_end, stride=0):
        self.dt, self.t_end, self.stride = float(dt), float(t_end), int(stride)
        self.n_steps = n_steps(self.t_end, self.dt)

    @classmethod
    def of_run(cls, cfg, durations=()):
        """The grid of a run of options ``cfg``: to -ssi_t_end when the user gave it, else to the
        longest of the sources' ``durations`` (a seismic record's length), else to -ssi_t_end's
        default. Made once, before any domain; the options are not changed."""
        t_end = cfg.t_end if cfg.user_set("t_end") or not len(durations) else max(durations)
        return cls(cfg.dt, t_end, cfg.output_stride)

    def time(self, n):
        """t_n = n dt, s."""
        return n * self.dt

    def times(self, first=0, last=None):
        """The times of steps first..last (default: to the last step), s."""
        last = self.n_steps if last is None else last
        return [self.time(n) for n in range(first, last + 1)]

    def writes(self, n):
        """Whether step n writes fields (-ssi_output_stride; 0: never)."""
        return bool(self.stride) and n % self.stride == 0

    def __repr__(self):
        return f"TimeGrid(dt={self.dt:g} s, {self.n_steps} steps to {self.time(self.n_steps):g} s, stride {self.stride})"
