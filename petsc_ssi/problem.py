"""The life cycle every problem kind shares (PyLith's Problem: initialise, solve, finalise).

``TransientProblem`` is the base of the three importable problems:

  petsc_ssi.bem.problem.BEMTransient        the half-space alone (-ssi_problem bem)
  petsc_ssi.fem.problem.FEMTransient        the structure alone (-ssi_problem fem)
  petsc_ssi.coupling.problem.SSITransient   structure and half-space coupled (-ssi_problem ssi)

Each one goes through the same stages, all collective:

  __init__(cfg, comm)   read and check every input (mesh, parts, options); nothing heavy, so bad
                        input fails here in one line on every rank
  setup()               assemble and factorise (BEM lag matrices, K and M, interface matrices)
  start()               the state at t = 0, outputs opened, recorder ready
  step(n)               one time step; returns the new state (PETSc Vecs, owned layout)
  finish()              outputs closed (receivers, sidecars, run record); returns the results

``run()`` does all of it and is what ``petsc-ssi`` calls; a script can step by itself:

    from petsc_ssi.petsc import init
    init()                                # PETSc from sys.argv: -options_file ... -ssi_...
    from petsc_ssi.problem import from_options
    p = from_options()                    # -ssi_problem and the rest from the options database
    p.setup(); p.start()
    for n in range(1, p.n_steps + 1):
        state = p.step(n)                 # look at, or act on, the state between steps
    results = p.finish()

``cfg`` is the resolved options (``options.resolve``); the options database stays the one
source of settings (no keyword arguments that bypass it).
"""
import signal
import time

import numpy as np

from .petsc import init, SSIError

SIGNALS = ("SIGTERM", "SIGINT", "SIGUSR1")


class _Signals:
    """Context manager: SIGTERM, SIGINT and SIGUSR1 (what schedulers send before the kill) set the
    flag ``got`` (the signal number) instead of killing the process (``TransientProblem._poll``
    reduces it over the ranks). The previous handlers come back on exit."""

    def __init__(self):
        self.got = 0
        self.old = {}

    def _handler(self, signum, frame):
        self.got = signum

    def __enter__(self):
        for name in SIGNALS:
            sig = getattr(signal, name)
            try:
                self.old[sig] = signal.signal(sig, self._handler)
            except (ValueError, OSError):        # not the main thread: leave the handlers alone
                pass
        return self

    def __exit__(self, *exc):
        for sig, h in self.old.items():
            signal.signal(sig, h)
        return False


class TransientProblem:
    """Base class; see the module docstring."""
    kind = ""

    def __init__(self, cfg, comm=None):
        PETSc = init()
        self.cfg = cfg
        self.comm = comm if comm is not None else PETSc.COMM_WORLD
        self.t_start = time.perf_counter()
        self.n = 0                      # the last step taken
        self.n_steps = 0
        self._state = "created"

    _METHOD = {"set up": "setup", "started": "start", "finished": "finish"}

    def check_output(self, also=()):
        """Collective: the output can be written and replaces nothing unless asked
        (``io.output.check_output``); called first by every constructor."""
        from .io.output import check_output
        if self.cfg.get("output"):
            check_output(self.cfg.output, self.comm, bool(self.cfg.get("output_overwrite")), also=also)

    def _advance(self, expected, new):
        if self._state != expected:
            raise SSIError(f"{type(self).__name__}: {self._METHOD[new]}() out of order, the problem is "
                           f"'{self._state}' (order: setup, start, step 1..n_steps, finish)")
        self._state = new

    def time(self, n):
        return n * self.cfg.dt

    def setup(self):
        raise NotImplementedError

    def start(self):
        raise NotImplementedError

    def step(self, n):
        raise NotImplementedError

    def finish(self):
        raise NotImplementedError

    def _check_step(self, n):
        if self._state not in ("started", "stepping"):
            raise SSIError(f"{type(self).__name__}: step {n} before start()")
        if n != self.n + 1 or n > self.n_steps:
            raise SSIError(f"{type(self).__name__}: step {n} out of order (last step {self.n} of {self.n_steps})")
        self._state = "stepping"

    # ------------------------------------------------------------ output that survives
    def write_partial(self, status):
        """Collective: the output file made readable with the results up to the last step and
        ``status`` (subclasses; the base has no output)."""

    def final_status(self):
        """'completed' after the last step, else how far a script stepped before finish()."""
        return "completed" if self.n == self.n_steps else f"finished after step {self.n} of {self.n_steps}"

    def _poll(self, sig):
        """Collective, one reduction per step: (the name of a signal any rank caught, or None;
        whether -ssi_output_flush seconds have passed since the last flush, by rank 0's clock)."""
        from mpi4py import MPI
        every = float(self.cfg.get("output_flush") or 0.0)
        due = 0
        if every and self.cfg.get("output") and self.comm.getRank() == 0:
            due = int(time.perf_counter() - getattr(self, "_last_flush", self.t_start) >= every)
        flags = np.array([sig.got, due], np.int64)
        self.comm.tompi4py().Allreduce(MPI.IN_PLACE, flags, op=MPI.MAX)     # elementwise
        return (signal.Signals(int(flags[0])).name if flags[0] else None), bool(flags[1])

    def _flush(self):
        """Collective: a 'running' flush; a failure (a reader holding the file) is a warning."""
        from .petsc import warn
        try:
            self.write_partial("running")
        except SSIError as exc:
            warn(f"could not update {self.cfg.output} during the run ({exc}); the run goes on", self.comm)
        self._last_flush = time.perf_counter()      # after the write: a slow write does not make every step flush

    def run(self):
        """Collective: setup, start, every step, finish; returns the results.

        While stepping, the output is made readable every -ssi_output_flush seconds, checked at the
        end of each step (attribute ``run_status`` 'running'); SIGTERM, SIGINT or SIGUSR1 stops
        the run at the end of the current step (after the last step the run just finishes), and
        a stop by a signal or by an SSIError (the divergence guard, a non-finite solution) writes
        the results up to the last step with ``run_status`` 'stopped ...' before the error is
        raised. Other exceptions (a bug, PETSc or MPI failures) write nothing more."""
        self.setup()
        self.start()
        with _Signals() as sig:                      # kept through finish: a signal there waits for the end
            try:
                for n in range(1, self.n_steps + 1):
                    self.step(n)
                    if n == self.n_steps:
                        break                        # the run is done: finish it, whatever arrived
                    name, due = self._poll(sig)
                    if name:
                        raise SSIError(f"stopped by {name} after step {n} of {self.n_steps} (t = {self.time(n):.6g} s)"
                                       + (f"; the results up to that step are in {self.cfg.output}"
                                          if self.cfg.get("output") else ""))
                    if due:
                        self._flush()
            except SSIError as exc:
                if self._state in ("started", "stepping"):
                    self.write_partial(f"stopped after step {self.n} of {self.n_steps}: {exc}")
                    self._state = "stopped"
                raise
            return self.finish()


KINDS = ("bem", "fem", "ssi")


def problem_class(kind):
    if kind == "bem":
        from .bem.problem import BEMTransient
        return BEMTransient
    if kind == "fem":
        from .fem.problem import FEMTransient
        return FEMTransient
    if kind == "ssi":
        from .coupling.problem import SSITransient
        return SSITransient
    raise SSIError(f"-ssi_problem {kind}: must be one of {'|'.join(KINDS)}")


def from_options(comm=None):
    """Collective: the problem the options database describes (-ssi_problem and its options,
    resolved and checked), constructed but not set up."""
    from . import driver, options
    kind = driver.problem_kind()
    cfg = options.resolve(driver.GROUPS[kind])
    return problem_class(kind)(cfg, comm)
