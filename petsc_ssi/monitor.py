"""Progress lines (-ssi_monitor) and PETSc log stages/events.

Progress comes from rank 0 only: what is being done, how far along, elapsed
time and an ETA from the mean rate so far. Log events make -log_view show
where time goes (assembly, factorisation, history sum, solve, I/O).
"""
import time

from .petsc import init, printf

_EVENTS = {}
_STAGES = {}


def event(name):
    """A PETSc log event (created once per name), usable as a context manager."""
    PETSc = init()
    if name not in _EVENTS:
        _EVENTS[name] = PETSc.Log.Event(name)
    return _EVENTS[name]


def stage(name):
    PETSc = init()
    if name not in _STAGES:
        _STAGES[name] = PETSc.Log.Stage(name)
    return _STAGES[name]


class staged:
    """Context manager: the PETSc log stage ``name`` pushed for the block (popped on errors too)."""

    def __init__(self, name):
        self.st = stage(name)

    def __enter__(self):
        self.st.push()
        return self.st

    def __exit__(self, *exc):
        self.st.pop()
        return False


class Progress:
    """Rank-0 progress of a loop of ``total`` items."""

    def __init__(self, what, total, enabled=True, every=0, comm=None, unit="step"):
        self.what = what
        self.total = max(int(total), 1)
        self.enabled = enabled
        self.every = every if every > 0 else max(1, self.total // 20)
        self.comm = comm
        self.unit = unit
        self.t0 = time.perf_counter()
        self.first = 0                   # items done before t0 (a restarted run)

    def update(self, k, extra=""):
        """Report after item ``k`` (1-based) when due."""
        if not self.enabled or (k % self.every and k != self.total):
            return
        el = time.perf_counter() - self.t0
        eta = el / max(k - self.first, 1) * (self.total - k)
        printf(f"[ssi] {self.what}: {self.unit} {k}/{self.total} ({100.0 * k / self.total:5.1f}%) "
               f"elapsed {fmt_time(el)} eta {fmt_time(eta)}{(' ' + extra) if extra else ''}", self.comm)

    def elapsed(self):
        return time.perf_counter() - self.t0


def fmt_time(s):
    if s < 60:
        return f"{s:.1f}s"
    if s < 3600:
        return f"{int(s // 60)}m{int(s % 60):02d}s"
    return f"{int(s // 3600)}h{int(s % 3600 // 60):02d}m"
