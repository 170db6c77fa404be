"""The life cycle every problem kind shares (PyLith's Problem: initialise, solve, finalise).

``TransientProblem`` is the base of the problem kinds; it knows none of them (the table of kinds,
``-ssi_problem`` -> class, is the application's: ``app/kinds.py``). The three kinds:

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

``run()`` does all of it and is what ``petsc-ssi`` calls; it also writes checkpoints
(-ssi_checkpoint_every, -ssi_checkpoint_interval, and on SIGTERM/SIGINT/SIGUSR1;
``io.checkpoint``), and with -ssi_restart ``start()`` resumes from one and ``run()`` goes on from
the step after it. A script can step by itself:

    from petsc_ssi.petsc import init
    init()                                # PETSc from sys.argv: -options_file ... -ssi_...
    from petsc_ssi.app.kinds import from_options
    p = from_options()                    # -ssi_problem and the rest from the options database
    p.setup(); p.start()
    for n in range(1, p.n_steps + 1):
        state = p.step(n)                 # look at, or act on, the state between steps
    results = p.finish()

``cfg`` is the resolved options (``options.resolve``); the options database stays the one
source of settings (no keyword arguments that bypass it).
"""
import os
import signal
import time

import numpy as np

from .petsc import init, SSIError, printf, collective_error, warn

SIGNALS = ("SIGTERM", "SIGINT", "SIGUSR1")


class _Signals:
    """Context manager: SIGTERM, SIGINT and SIGUSR1 (what schedulers send before the kill) set the
    flag ``got`` (the signal number) instead of killing the process (``TransientProblem._poll``
    reduces it over the ranks). The previous handlers come back on exit."""

    def __init__(self):
        self.got = 0
        self.at = None
        self.old = {}

    def _handler(self, signum, frame):
        self.got = signum
        self.at = time.perf_counter()            # when it came (the stop's duration is reported)

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


class CheckpointObserver:
    """An observer of the recorder (``io.recorder`` protocol) that ``TransientProblem.run`` adds:
    after each step but the last, one collective poll (``_poll``: a signal any rank caught;
    -ssi_output_flush and -ssi_checkpoint_interval due by rank 0's clock), a checkpoint every
    -ssi_checkpoint_every steps and when the interval is due; on a signal the run stops
    (``TransientProblem._stop``: the output, then a checkpoint, then SSIError); a due flush makes
    the output readable. A script that steps by itself gets none of this."""

    def __init__(self, problem, sig):
        self.p, self.sig = problem, sig
        self.every = int(problem.cfg.get("checkpoint_every") or 0)

    def observe(self, n, t, step):
        p = self.p
        if n == p.n_steps:
            return                                   # the run is done: finish it, whatever arrived
        name, due, ck_due = p._poll(self.sig)
        if name:
            p._stop(name, self.sig)                  # raises SSIError
        if ck_due or (self.every and n % self.every == 0):
            p.write_checkpoint()
        elif due:
            p._flush()


def check_names(cfg, outputs):
    """SSIError (the same on every rank: names only) if the checkpoint (-ssi_checkpoint, '%d' any
    step) or -ssi_lags_save's files would replace an output of the run or its sidecars, or each
    other: a file written by one part of the run must not be another's. Files are compared by what
    they are (``io.output.file_keys``: the real path and the inode), so a name that reaches an
    output through a symbolic link, a linked directory or a hard link is that output."""
    import re
    from .io.output import output_files, file_keys
    from .io import checkpoint
    from .io.lock import lock_path
    owned = {}                                    # key of a file -> (its name, what writes it)

    def owner(f):
        for k in file_keys(f):
            if k in owned:
                return owned[k]
        return None

    for o in outputs:
        for f in output_files(o) + [lock_path(o)]:
            who = f"the output {o}" if f == o else f"a sidecar of the output {o}"
            for k in file_keys(f):
                owned.setdefault(k, (f, who))
    lags = cfg.get("lags_save") or ""
    if lags:
        for f in (lags, lags + ".json", lags + ".tmp", lags + ".json.tmp", lock_path(lags)):
            hit = owner(f)
            if hit:
                raise SSIError(f"-ssi_lags_save {lags}: would replace {hit[0]}, {hit[1]}; give the lag file "
                               "a name of its own")
            for k in file_keys(f):
                owned[k] = (f, f"-ssi_lags_save's {f}")
    ck = cfg.get("checkpoint") or ""
    if ck or outputs:
        pattern = os.path.realpath(checkpoint.checkpoint_path(cfg) or "")
        rx = re.compile("^" + "[0-9]+".join(re.escape(part) for part in pattern.split("%d")) + r"(\.tmp)?$")
        for key, (f, who) in owned.items():
            if key[0] == "path" and rx.match(key[1]):
                raise SSIError(f"-ssi_checkpoint {ck or pattern}: would replace {f}, {who}; a checkpoint needs "
                               "a name of its own")
        if "%d" not in pattern:
            hit = owner(pattern) or owner(pattern + ".tmp")
            if hit:
                raise SSIError(f"-ssi_checkpoint {ck or pattern}: would replace {hit[0]}, {hit[1]}; a checkpoint "
                               "needs a name of its own")


def foreign_checkpoints(cfg, comm, run_id, overwrite):
    """Collective: SSIError in one line if the checkpoint pattern of -ssi_checkpoint ('%d' in the
    name: one file per step) matches files that exist and are not this run's (another run with the
    same pattern, or a restart's other run): the run would replace them one by one without a word.
    A restart may replace its own run's (the same run id); -ssi_output_overwrite any."""
    import re
    ck = cfg.get("checkpoint") or ""
    if "%d" not in ck or overwrite:
        return
    err = None
    if comm.getRank() == 0:
        d = os.path.dirname(os.path.abspath(ck)) or "."
        base = os.path.basename(ck)
        rx = re.compile("^" + "[0-9]+".join(re.escape(part) for part in base.split("%d")) + "$")
        found = sorted(f for f in (os.listdir(d) if os.path.isdir(d) else ()) if rx.match(f))
        for f in found:
            path = os.path.join(d, f)
            rid = None
            if run_id:
                try:
                    import h5py
                    with h5py.File(path, "r") as h:
                        v = h.attrs.get("run_id", "")
                        rid = v.decode() if isinstance(v, bytes) else str(v)
                except Exception:  # noqa: BLE001 -- unreadable: not this run's
                    rid = None
            if rid is None or rid != run_id:
                err = (f"-ssi_checkpoint {ck}: {path} exists and is not this run's ({len(found)} file(s) of this "
                       "pattern: another run's checkpoints, which this run would replace step by step); add "
                       "-ssi_output_overwrite to replace them, or choose another -ssi_checkpoint")
                break
    collective_error(err, comm)


def _size(b):
    """Bytes as MB or GB (3 digits)."""
    return f"{b / 1e9:.3g} GB" if b >= 1e9 else f"{b / 1e6:.3g} MB"


def no_output_refused(cfg, what):
    """SSIError for -ssi_output '' in a run whose results live in its file (BEM, coupled): such a
    run ended after the assembly in an HDF5 error. Only a FEM run takes '' (no output)."""
    if not str(cfg.get("output") or "").strip():
        raise SSIError(f"-ssi_output '': {what} run keeps its results in its output file; give a file name "
                       "(only a FEM run, -ssi_problem fem, runs without one)")


class TransientProblem:
    """Base class; see the module docstring."""
    kind = ""

    def __init__(self, cfg, comm=None):
        PETSc = init()
        self.cfg = cfg
        self.comm = comm if comm is not None else PETSc.COMM_WORLD
        self.t_start = time.perf_counter()
        self.n = 0                      # the last step taken
        self.grid = None                # the time grid (timegrid.TimeGrid), made by the subclass
        self._state = "created"
        self.restart = None             # the header of -ssi_restart's checkpoint (check_output)
        self.run_id = ""                # written into the outputs and checkpoints (check_output)
        self._locks = []                # the lock files of the run's outputs (check_output)
        self._key = None
        from .petsc import set_huge_pages
        self.huge_pages = set_huge_pages(cfg.get("huge_pages", "auto"))    # before the large arrays

    _METHOD = {"set up": "setup", "started": "start", "finished": "finish"}

    def check_output(self, also=()):
        """Collective: the output can be written and replaces nothing unless asked
        (``io.output.check_output``), the checkpoint location too, and -ssi_restart's checkpoint
        belongs to this run (``io.checkpoint.check_restart``: its options, its checksums, and an
        existing output of the same run id); no checkpoint or lag file named like an output or
        sidecar of the run; then the run's files are locked (``io.lock``) for the run's duration.
        Called first by every constructor. A restart continues the output of the interrupted run,
        so that one may exist."""
        from .io.output import check_output
        from .io import checkpoint
        cfg = self.cfg
        outputs = ([cfg.output] + list(also)) if cfg.get("output") else []
        if cfg.get("restart"):
            self.restart = checkpoint.check_restart(cfg, self.comm, self.kind, outputs=outputs)
            self.run_id = str(self.restart.get("run_id") or "")
        elif cfg.get("reproducible"):               # identical reruns give identical files: the id of the options
            import hashlib
            import json
            self.run_id = hashlib.sha256(json.dumps(checkpoint.run_key(cfg), sort_keys=True).encode()).hexdigest()[:32]
        else:
            import uuid
            self.run_id = self.comm.tompi4py().bcast(uuid.uuid4().hex if self.comm.getRank() == 0 else None, root=0)
        overwrite = bool(cfg.get("output_overwrite"))
        if cfg.get("output"):
            check_output(cfg.output, self.comm, overwrite or self.restart is not None, also=also)
        ck = checkpoint.checkpoint_path(cfg, 0)
        if ck and (cfg.get("checkpoint") or cfg.get("checkpoint_every") or cfg.get("checkpoint_interval")):
            from .io.output import same_file
            same = self.restart is not None and same_file(ck, cfg.restart)
            check_output(ck, self.comm, overwrite or same or "%d" in (cfg.get("checkpoint") or ""),
                         what="-ssi_checkpoint")
        check_names(cfg, outputs)
        foreign_checkpoints(cfg, self.comm, self.run_id if self.restart is not None else "", overwrite)
        from .io import lock
        paths = list(outputs)
        if cfg.get("checkpoint"):
            paths.append(cfg.checkpoint)                 # the pattern itself: ck-%d.h5.lock
        if cfg.get("lags_save"):
            paths.append(cfg.lags_save)
        self._locks = lock.acquire(paths, self.comm, self) if paths else []

    def release_locks(self):
        """The locks of the run's files given back (``io.lock``): at the end of ``finish`` (the run is
        done), and ``run`` on any error; a script that steps by itself and stops before finish()
        may call it (else: at exit)."""
        from .io import lock
        lock.release(getattr(self, "_locks", ()), self.comm)
        self._locks = []

    def output_bytes(self):
        """{what: bytes} this run will write (estimates; the subclasses say what they write)."""
        return {}

    def check_disk(self):
        """Collective, at the end of every constructor (before the assembly): refuse in one line a run
        whose estimated output (``output_bytes``) exceeds the free space of the output's file system
        (shutil.disk_usage of its directory, rank 0). -ssi_disk_check 0 skips it; a quota is not seen
        (the per-snapshot check of ``petsc.ensure_space`` and the write errors remain)."""
        import shutil
        from .petsc import collective
        cfg = self.cfg
        if not cfg.get("disk_check", True) or not cfg.get("output"):
            return
        with collective(self.comm, "checking the disk space"):
            if self.comm.getRank() == 0:
                parts = {k: float(v) for k, v in self.output_bytes().items() if v > 0}
                left = 1.0
                if self.restart is not None and self.grid is not None and self.grid.n_steps:
                    left = max(0.0, 1.0 - int(self.restart["step"]) / self.grid.n_steps)
                need = 1.1 * left * sum(parts.values()) + 1e6       # the margin of petsc.ensure_space
                d = os.path.dirname(os.path.abspath(cfg.output))
                while not os.path.isdir(d) and os.path.dirname(d) != d:
                    d = os.path.dirname(d)         # the directory may be made by the run
                free = shutil.disk_usage(d).free
                if need > free:
                    what = ", ".join(f"{k} {_size(v)}" for k, v in parts.items())
                    raise SSIError(f"-ssi_output {cfg.output}: the run needs about {_size(need)} of disk ({what}; "
                                   f"10 % and 1 MB more for HDF5) and {d} has {_size(free)} free; free space, write "
                                   "fewer snapshots (-ssi_output_stride), or skip this check with -ssi_disk_check 0")

    @staticmethod
    def field_bytes(nodes, fields, grid):
        """Bytes of ``fields`` 3-vectors per node (float64) over the snapshots of ``grid``, with the
        PETSc viewer's own 4 kB per dataset (measured: 3.3 kB on the quarter model's files)."""
        snaps = grid.n_steps // grid.stride if grid.stride else 0
        return (8.0 * 3 * nodes + 4096.0) * fields * snaps

    # ------------------------------------------------------------ checkpoint and restart
    def checkpoint_state(self):
        """({name: Vec}, {name: array on rank 0}): what the next step needs (subclasses)."""
        raise NotImplementedError

    def restore_state(self, reader):
        """Collective: the state of a checkpoint (``io.checkpoint.Reader``) into this problem, after
        start() made its objects (subclasses)."""
        raise NotImplementedError

    def write_checkpoint(self, flush=True):
        """Collective: a checkpoint after the last step taken; returns its path (None without an
        output or -ssi_checkpoint). ``flush``: make the output readable first (a stop has just
        written it)."""
        from .io import checkpoint
        from .monitor import staged
        path = checkpoint.checkpoint_path(self.cfg, self.n)
        if path is None:
            return None
        if self._key is None:
            self._key = checkpoint.run_key(self.cfg, grid=self.grid)   # (a record-long run: the end it derived)
        with staged("SSI checkpoint"):
            if flush and self.cfg.get("output") and not self._flush():
                # the output holds every snapshot a checkpoint lists, even after SIGKILL: without that
                # flush no checkpoint (the previous one stays)
                from .petsc import warn
                warn(f"no checkpoint after step {self.n}: the output could not be updated first", self.comm)
                self._last_ckpt = time.perf_counter()          # tried: the next one at the next interval
                return None
            why = checkpoint.not_ours(path, self.comm, getattr(self, "run_id", ""),
                                      bool(self.cfg.get("output_overwrite")))
            if why:                                    # never replace a file this run did not write
                from .petsc import warn
                warn(f"no checkpoint after step {self.n}: {why}", self.comm)
                self._last_ckpt = time.perf_counter()
                return None
            vecs, serial = self.checkpoint_state()
            checkpoint.write(path, self.comm, self.n, self.n_steps, self.kind, self._key, vecs, serial,
                             run_id=getattr(self, "run_id", ""))
        self._last_ckpt = time.perf_counter()
        if self.cfg.get("monitor"):
            printf(f"[ssi] checkpoint after step {self.n} of {self.n_steps}: {path}")
        return path

    def _open_restart(self):
        """Collective, first in start(): the -ssi_restart checkpoint's reader (None without one)."""
        self._reader = None
        if self.restart is not None:
            from .io.checkpoint import Reader
            self._reader = Reader(self.cfg.restart, self.comm)
        return self._reader

    @staticmethod
    def _output_state(prefix, out):
        """{prefix_times, prefix_fields} of an Output (or nothing without one), for a checkpoint."""
        if out is None:
            return {}
        return {f"{prefix}_{k}": v for k, v in out.state().items()}

    def _resume(self):
        """Collective, at the end of start(): with -ssi_restart, the checkpoint's state; the run goes
        on from the step after it."""
        if self._reader is None:
            return
        try:
            self.restore_state(self._reader)
        finally:
            self._reader.close()
            self._reader = None
        self.n = int(self.restart["step"])
        self._state = "stepping"
        printf(f"[ssi] restarted from {self.cfg.restart} after step {self.n} of {self.n_steps} "
               f"(written on {self.restart['ranks']} rank(s), running on {self.comm.getSize()})")

    def _advance(self, expected, new):
        if self._state != expected:
            raise SSIError(f"{type(self).__name__}: {self._METHOD[new]}() out of order, the problem is "
                           f"'{self._state}' (order: setup, start, step 1..n_steps, finish)")
        self._state = new

    def time(self, n):
        """t_n of the run's time grid, s."""
        return self.grid.time(n)

    @property
    def n_steps(self):
        return self.grid.n_steps if self.grid is not None else 0

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
    io_event = "SSI_IO"           # the PETSc log event of the run's output

    def output_parts(self, res):
        """[(Output or None, {receivers, attrs, groups, record})] of the run's results ``res``: one
        item per output file (subclasses; the base has none)."""
        return []

    def written(self, res):
        """After the final write (subclasses: plots, the log line)."""

    def write_results(self, res, status="completed", final=True):
        """Collective: every output of the run (``output_parts``) with its receivers, attributes,
        serial groups and run record, and ``status``; ``final``: closed (else flushed: readable,
        still open). The one writer of results every problem uses."""
        from .monitor import event
        with event(self.io_event):
            for out, parts in self.output_parts(res):
                if out is not None:
                    (out.close if final else out.flush)(status=status, **parts)
        if final:
            self.written(res)

    def write_partial(self, status):
        """Collective: the output file made readable with the results up to the last step and
        ``status`` (subclasses; the base has no output)."""

    def final_status(self):
        """'completed' after the last step, else how far a script stepped before finish()."""
        return "completed" if self.n == self.n_steps else f"finished after step {self.n} of {self.n_steps}"

    def _poll(self, sig):
        """Collective, one reduction per step: (the name of a signal any rank caught, or None;
        whether -ssi_output_flush seconds have passed since the last flush; whether
        -ssi_checkpoint_interval seconds have passed since the last checkpoint), by rank 0's clock."""
        from mpi4py import MPI
        every = float(self.cfg.get("output_flush") or 0.0)
        ck_every = float(self.cfg.get("checkpoint_interval") or 0.0)
        due = ck_due = 0
        if self.comm.getRank() == 0:
            now = time.perf_counter()
            if every and self.cfg.get("output"):
                due = int(now - getattr(self, "_last_flush", self.t_start) >= every)
            if ck_every:
                ck_due = int(now - getattr(self, "_last_ckpt", self.t_start) >= ck_every)
        flags = np.array([sig.got, due, ck_due], np.int64)
        self.comm.tompi4py().Allreduce(MPI.IN_PLACE, flags, op=MPI.MAX)     # elementwise
        return (signal.Signals(int(flags[0])).name if flags[0] else None), bool(flags[1]), bool(flags[2])

    def _stop(self, name, sig):
        """Collective, on a signal any rank caught: the output first (the cheap part, which keeps
        every step done: 0.1 to 0.4 s on the small cases), then the checkpoint (written to FILE.tmp
        and renamed: a kill during it leaves the previous one), then SSIError. Both are collective
        writes only, no solve or reduction that waits on another rank's progress. mpirun sends
        SIGKILL odls_base_sigkill_timeout seconds (default 1) after it forwards SIGTERM; SIGUSR1
        it forwards without a kill (README: signals)."""
        t0 = sig.at if sig.at is not None else time.perf_counter()
        n, N = self.n, self.n_steps
        msg = f"stopped by {name} after step {n} of {N} (t = {self.time(n):.6g} s)"
        if self.cfg.get("output"):
            msg += f"; the results up to that step are in {self.cfg.output}"
            self.write_partial(f"stopped after step {n} of {N}: {msg}")
        self._state = "stopped"
        t1 = time.perf_counter()
        path = self.write_checkpoint(flush=False)
        t2 = time.perf_counter()
        if path:
            msg += f"; resume with -ssi_restart {path}"
        took = ([f"output written {t1 - t0:.2g} s after the signal"] if self.cfg.get("output") else []) + \
            ([f"checkpoint {t2 - t0:.2g} s"] if path else [])
        msg += f" ({', '.join(took)})" if took else ""
        raise SSIError(msg)

    def _flush(self):
        """Collective: a 'running' flush; a failure (a full disk) is a warning. Returns whether it
        succeeded (the same on every rank)."""
        from .petsc import warn
        ok = True
        try:
            self.write_partial("running")
        except SSIError as exc:
            ok = False
            warn(f"could not update {self.cfg.output} during the run ({exc}); the run goes on", self.comm)
        self._last_flush = time.perf_counter()      # after the write: a slow write does not make every step flush
        return ok

    def loop_estimate(self):
        """(seconds of the whole time loop, seconds per step, what it covers) predicted before the
        run, or None where the kind has no model (the BEM's: ``bem.cost.loop_terms``, the model
        ``petsc-ssi estimate`` evaluates)."""
        prob = getattr(self, "prob", None)
        est = getattr(prob, "loop_estimate", None)
        return None if est is None else (est[0], est[1], "the soil's BEM")

    def loop_model(self):
        """k -> the predicted seconds of the first k steps (None without a model)."""
        return getattr(getattr(self, "prob", None), "loop_model", None)

    # the coupled run prints its loop line after the structure's factorisation, whose solves it times
    defer_loop_line = False

    def expect_progress(self):
        """The progress line (-ssi_monitor) compares the measured time of the steps with the run's
        own prediction (``loop_estimate``'s model for the first k steps) and warns once when it runs
        far above it (``monitor.slow_warning``: a loaded machine, oversubscribed ranks)."""
        prob = getattr(self, "prob", None)
        model = self.loop_model()
        rec = getattr(self, "rec", None)
        est = self.loop_estimate()
        if model is None or rec is None or est is None:
            return
        rec.progress.progress.expect(model, getattr(prob, "ranks_here", 1),
                                     f"the run's prediction ({est[2]}, {getattr(prob, 'loop_source', 'bem/cost.py')})",
                                     getattr(prob, "loop_fit", None))

    def announce_loop(self):
        """Collective, before the set-up: one line with the number of steps and, where a model
        exists, the predicted time of the loop; SSIError beyond -ssi_max_steps (a run whose t_end
        comes from elsewhere, a seismic record's length, is checked here; -ssi_t_end itself when
        the options resolve). The coupled run prints the line in its set-up (``defer_loop_line``)."""
        limit = int(self.cfg.get("max_steps", 0) or 0)
        if limit and self.n_steps > limit:
            raise SSIError(f"the run to t = {self.time(self.n_steps):.6g} s with -ssi_dt {self.grid.dt:g} is "
                           f"{self.n_steps:.4g} time steps, more than -ssi_max_steps {limit}; check t_end and dt, "
                           "or raise -ssi_max_steps to run them")
        st = int(self.cfg.get("output_stride", 0) or 0)
        if st > self.n_steps and self.cfg.get("output") and self.cfg.user_set("output_stride"):
            warn(f"-ssi_output_stride {st} is more than the run's {self.n_steps} steps: no field snapshot is written "
                 "(receivers only; -ssi_output_stride 0 says so without this line)")
        if not self.defer_loop_line:
            self.print_loop_line()

    def print_loop_line(self):
        """One line: the steps to go and, where a model exists, their predicted time (the model of
        ``petsc-ssi estimate``: the same numbers for the same run and rank count)."""
        from .monitor import fmt_time
        todo = self.n_steps - self.n
        est = self.loop_estimate()
        line = (f"[ssi] time loop: {todo} steps of {self.grid.dt:.4g} s to t = {self.time(self.n_steps):.6g} s")
        if est is not None:
            model = self.loop_model()
            left = est[0] - (model(self.n) if model is not None and self.n else 0.0)
            line += (f"; predicted {f'{left:.3g} s' if left < 60 else fmt_time(left)} ({est[2]}: about {est[1]:.2g} s per step once every stored lag "
                     "is in the history sum, and the field snapshots; the model of petsc-ssi estimate, "
                     f"{getattr(getattr(self, 'prob', None), 'loop_source', 'bem/cost.py')})")
        printf(line)

    def run(self):
        """Collective: setup, start, every step, finish; returns the results.

        While stepping, the output is made readable every -ssi_output_flush seconds, checked at the
        end of each step (attribute ``run_status`` 'running'), and a checkpoint is written every
        -ssi_checkpoint_every steps and -ssi_checkpoint_interval seconds. SIGTERM, SIGINT or
        SIGUSR1 stops the run at the end of the current step, the output written first, then a
        checkpoint (after the last step the run just finishes); a stop by a signal or by an
        SSIError (the divergence guard, a non-finite solution) writes the results up to the last
        step with ``run_status`` 'stopped ...' before the error is raised. Other exceptions (a bug,
        PETSc or MPI failures) write nothing more. With -ssi_restart the steps start after the
        checkpoint's. The locks of the run's files are given back at the end, whatever happened; after a
        finished run the soil's lag matrices too (``release_lags``)."""
        try:
            res = self._run()
        finally:
            self.release_locks()
        self.release_lags()
        return res

    def release_lags(self):
        """Collective: free the soil's lag matrices (``bem.march.Marcher.release``) once the run is done. Their
        python Mats and contexts hold each other through PETSc, out of the collector's reach: a script that runs
        problem after problem in one process (a parameter study, ``petsc-ssi impedance``'s modes, the tests)
        kept every run's lags until exit. Not on an error, which may have stopped some ranks only."""
        march = getattr(self, "march", None)
        if march is not None:
            march.release()

    def _run(self):
        self.announce_loop()
        self.setup()
        self.start()
        self.expect_progress()
        with _Signals() as sig:                      # kept through finish: a signal there waits for the end
            ck = self.rec.add(CheckpointObserver(self, sig))
            try:
                for n in range(self.n + 1, self.n_steps + 1):
                    self.step(n)                     # the recorder's observers checkpoint and flush
            except SSIError as exc:
                if self._state in ("started", "stepping"):        # a stop by a signal wrote it already
                    self.write_partial(f"stopped after step {self.n} of {self.n_steps}: {exc}")
                    self._state = "stopped"
                raise
            finally:
                self.rec.extra.remove(ck)
            return self.finish()
