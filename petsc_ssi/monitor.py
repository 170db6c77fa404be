"""Progress lines (-ssi_monitor) and PETSc log stages/events.

Progress comes from rank 0 only: what is being done, how far along, elapsed
time and an ETA from the mean rate so far. Log events make -log_view show
where time goes (assembly, factorisation, history sum, solve, I/O).
"""
import time

from .petsc import init, printf

_EVENTS = {}
_STAGES = {}
_CLOCK = time.perf_counter          # the compile clock's own (tests replace ``monitor.time.perf_counter``)
_COMPILE = None


def compile_seconds():
    """Seconds this process has spent compiling numba kernels (not loading them from the cache) since
    the first call, outermost compilations only (a kernel's callees compile inside it): numba's
    'numba:compile' events. A loop whose kernels compile in it (the first run of a version, a kernel
    no earlier run used) is not slow for its cost model; ``Progress`` leaves this time out of its
    slow-run warning. 0.0 where numba has no event API."""
    global _COMPILE
    if _COMPILE is None:
        try:
            from numba.core import event as ev
        except ImportError:
            _COMPILE = False
            return 0.0

        class Clock(ev.Listener):
            depth, total, t = 0, 0.0, 0.0

            def on_start(self, event):
                if self.depth == 0:
                    self.t = _CLOCK()
                self.depth += 1

            def on_end(self, event):
                self.depth -= 1
                if self.depth == 0:
                    self.total += _CLOCK() - self.t

        _COMPILE = Clock()
        ev.register("numba:compile", _COMPILE)
    return _COMPILE.total if _COMPILE else 0.0


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
        if len(_STAGES) == 1:
            _hide_unused_stage(PETSc, _STAGES[name])
    return _STAGES[name]


def _petsc_library():
    """The path of the PETSc shared library this process has loaded (Linux: /proc/self/maps), or None."""
    try:
        with open("/proc/self/maps") as fh:
            for line in fh:
                path = line.split()[-1]
                base = path.rsplit("/", 1)[-1]
                if base.startswith("libpetsc") and ".so" in base:
                    return path
    except OSError:
        pass
    return None


def _hide_unused_stage(PETSc, first):
    """PETSc 3.18 with petsc4py registers a stage 1 that nothing pushes, and -log_view printed it as
    an empty 'Event Stage 1: Unknown' (issue 30). Where petsc_ssi's first stage gets the id 2 on 3.18,
    stage 1 is that one (not petsc_ssi's, which registers its stages here only): it is made invisible
    (PetscLogStageSetVisible through ctypes; petsc4py has no handle on a stage it did not create).
    Any other version, id or failure leaves -log_view as it is."""
    if tuple(PETSc.Sys.getVersion()[:2]) != (3, 18) or first.id != 2:
        return
    lib = _petsc_library()
    if lib is None:
        return
    try:
        import ctypes
        ctypes.CDLL(lib).PetscLogStageSetVisible(ctypes.c_int(1), ctypes.c_int(0))
    except (OSError, AttributeError):
        pass


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
        self.model = None                # k -> predicted seconds of items 1..k (``expect``)
        self.model_fit = None            # how to refit it (``slow_warning``)
        self._last = None                # (item, elapsed) of the last report with a model (the eta's pace)
        self.warned = False

    def expect(self, model, ranks_here=1, what="the run's prediction", fit=None):
        """Compare the measured time with ``model`` (k -> predicted seconds of items 1..k) at every
        report, and warn once when it runs more than SLOW times above it (``slow_warning``; ``fit``: how
        to refit the model, its default when None), the time spent compiling numba kernels in the loop
        left out (``compile_seconds``); ``ranks_here``: the ranks sharing this node's cores. The eta of
        the progress line then follows the model's shape (a history sum whose steps grow with the lags
        in use) at the pace measured since the last report (the first steps' one-time costs, first
        touches of the kept states, not extrapolated), not a straight line from the steps done."""
        self.model, self.ranks_here, self.model_what, self.model_fit = model, int(ranks_here), what, fit
        self.compile0 = compile_seconds()

    def update(self, k, extra=""):
        """Report after item ``k`` (1-based) when due (the line with -ssi_monitor; the slow-run warning
        against the model with or without it: a run 3-10 times slower on shared cores said nothing
        without -ssi_monitor, issue 44)."""
        if k % self.every and k != self.total:
            return
        if not self.enabled and (self.model is None or self.warned):
            return
        el = time.perf_counter() - self.t0
        if self.enabled:
            eta = el / max(k - self.first, 1) * (self.total - k)
            if self.model is not None:          # the model's remaining steps at the pace of the last report's
                k0, e0 = self._last or (self.first, 0.0)                         # steps (one-time costs behind)
                done = self.model(k) - self.model(k0)
                if done > 0 and el > e0:
                    eta = (el - e0) * (self.model(self.total) - self.model(k)) / done
            self._last = (k, el)
            printf(f"[ssi] {self.what}: {self.unit} {k}/{self.total} ({100.0 * k / self.total:5.1f}%) "
                   f"elapsed {fmt_time(el)} eta {fmt_time(eta)}{(' ' + extra) if extra else ''}", self.comm)
        if self.model is not None and not self.warned:
            pred = self.model(k) - self.model(self.first)
            msg = slow_warning(el - (compile_seconds() - self.compile0), pred, k - self.first, self.ranks_here,
                               self.model_what, self.unit, fit=self.model_fit)
            if msg:
                self.warned = True
                from .petsc import warn
                warn(msg, self.comm)

    def elapsed(self):
        return time.perf_counter() - self.t0


SLOW = 3.0            # measured / predicted above which the progress line warns
SLOW_MIN_S = 2.0      # ... once the loop has run this long (start-up noise) and over 5 items


def slow_warning(elapsed, predicted, items, ranks_here, what="the run's prediction", unit="step", load=None,
                 cores=None, fit=None):
    """The warning (one line) when ``elapsed`` seconds for ``items`` items run more than SLOW times
    above ``predicted``, naming the likely cause and what to try, or None. ``ranks_here``: the
    ranks sharing this node's cores; ``load``: the 1-minute load average and ``cores`` this machine's
    (read here when None); ``fit``: how to refit the model (default: the dense store's constants,
    jobscripts/calibrate.py)."""
    import os
    if items < 5 or elapsed < SLOW_MIN_S or not predicted > 0 or elapsed <= SLOW * predicted:
        return None
    cores = cores or os.cpu_count() or 1
    if load is None:
        try:
            load = os.getloadavg()[0]
        except OSError:
            load = float("nan")
    head = (f"the {unit}s run {elapsed / predicted:.1f} times slower than {what} ({fmt_time(elapsed)} for {items} "
            f"{unit}s, predicted {fmt_time(predicted)}): ")
    if ranks_here > cores:
        return head + (f"{ranks_here} ranks share {cores} cores (oversubscribed); run with at most {cores} ranks per "
                       "node (mpirun -n)")
    if load > 1.25 * cores:
        return head + (f"the machine is loaded (load average {load:.1f} on {cores} cores: other work shares the cores, "
                       f"and {ranks_here} rank(s) of this run wait for them); run it when the machine is idle, or with "
                       "fewer ranks (-n 1 may then be the faster)")
    return head + (f"the machine is not visibly loaded (load average {load:.1f} on {cores} cores), so the cost model's "
                   "constants may not fit it or this case: check petsc-ssi estimate, and fit the constants with "
                   + (fit or "jobscripts/calibrate.py (-ssi_estimate_constants)"))


def fmt_time(s):
    if s < 1:                   # (a small case's estimate: '0.0s' for 0.04 s said nothing)
        return f"{s:.3f}s"
    if s < 60:
        return f"{s:.1f}s"
    if s < 3600:
        return f"{int(s // 60)}m{int(s % 60):02d}s"
    return f"{int(s // 3600)}h{int(s % 3600 // 60):02d}m"
