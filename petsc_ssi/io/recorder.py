"""What a run keeps, for the three problem kinds (BEM, FEM, coupled): one recorder, a list of
observers with one small protocol (``Recorder``; PyLith's observers). The observers of a domain
live beside it (issue 40: ``io/`` holds files, formats and the recorder, and imports neither
``bem/`` nor ``fem/``):

  bem.recorder.SoilRecorder       the soil's mesh, fields and receiver series
  fem.recorder.StructureRecorder  the structure's mesh, fields and receiver series
  fem.forces, fem.demands         member forces; base shear, overturning moment, drifts
  InterfaceSeries    per-step arrays of the coupling (a dict of lists, rank 0's copy)
  NormHistory        |u| of every step; ProgressLine the -ssi_monitor line

A problem hands each step to ``Recorder.step``; fields are written on the steps its time
grid says (``TimeGrid.writes``: every -ssi_output_stride steps), receivers every step. A new
output is a new observer. Collective unless said otherwise.
"""
import numpy as np

from ..monitor import Progress


class InterfaceSeries:
    """The coupling's interface record: a dict of lists, rank 0's copy (every rank holds the same).
    The ``nodal`` keys (one value per interface dof or node: u_f, u_b, p, ...) are kept every
    ``stride`` steps (steps n with n % stride == 0, listed in ``nodal_steps``), the others
    (resultants, counts) every step."""

    def __init__(self, keys, nodal=(), stride=1):
        self.series = {k: [] for k in keys}
        self.nodal = set(k for k in nodal if k in self.series)
        self.stride = max(int(stride), 1)
        self.nodal_steps = []

    def observe(self, n, t, step):
        res = step.get("interface")
        if res is None:
            return
        keep = n % self.stride == 0
        if keep:
            self.nodal_steps.append(n)
        for k in self.series:
            if keep or k not in self.nodal:
                self.series[k].append(res[k])

    def state(self, n_times):
        s = {"interface_" + k: np.asarray(v) for k, v in self.series.items()}
        s["interface_nodal_steps"] = np.asarray(self.nodal_steps, np.int64)
        return s

    def restore(self, s, n):
        for k in self.series:
            self.series[k] = list(np.asarray(s["interface_" + k]))
        steps = s.get("interface_nodal_steps")
        self.nodal_steps = ([int(k) for k in steps] if steps is not None
                            else list(range(n - len(self.series[next(iter(self.nodal))]) + 1, n + 1))
                            if self.nodal else [])

    def arrays(self):
        a = {k: np.asarray(v) for k, v in self.series.items()}
        a["nodal_steps"] = np.asarray(self.nodal_steps, np.int64)
        return a


class StepClock:
    """The wall time of every step (seconds from the end of the previous step's records to the end of
    this one's, on this rank): what a long record's per-step cost is, and whether it stays flat."""

    def __init__(self):
        import time
        self._now = time.perf_counter
        self.last = None
        self.values = []

    def observe(self, n, t, step):
        now = self._now()
        self.values.append(now - self.last if self.last is not None else np.nan)
        self.last = now

    def start(self):
        """Call at the start of the time loop (the first step's time is then measured too)."""
        self.last = self._now()

    def state(self, n_times):
        return {"step_wall": np.asarray(self.values, float)}

    def restore(self, s, n):
        self.values = [float(x) for x in s.get("step_wall", [])]
        self.last = None


class NormHistory:
    """|u| of every step (the divergence guard and -ssi_monitor read it)."""

    def __init__(self):
        self.values = []

    def observe(self, n, t, step):
        if step.get("norm") is not None:
            self.values.append(step["norm"])

    def state(self, n_times):
        return {"unorm": np.asarray(self.values, float)}

    def restore(self, s, n):
        self.values = [float(x) for x in s["unorm"]]


class ProgressLine:
    """The -ssi_monitor line (``monitor.Progress``): what, how far, how long to go."""

    def __init__(self, cfg, comm, what, n_steps):
        self.progress = Progress(what, n_steps, enabled=cfg.monitor, every=cfg.monitor_every, comm=comm)

    def observe(self, n, t, step):
        self.progress.update(n, step.get("status", ""))

    def restore(self, s, n):
        self.progress.first = n


class Recorder:
    """Collective: what a run keeps, as a list of observers (PyLith's observers) with one protocol:

      initial(t, step, write) the state at t = 0 (step 0, before the first step): series that
                             start at rest (the structure's receivers, member forces, demands);
                             ``write``: its fields too
      observe(n, t, step)    step n at time t; ``step`` holds what the problem gives: 'soil' (u, p)
                             Vecs, 'structure' (u, v) Vecs, 'interface' (a dict), 'norm', 'status'
      snapshot(n, t, step)   the fields of a step the time grid writes (``TimeGrid.writes``),
                             after every observer saw the step (the series are whole before a
                             snapshot can fail on a full disk)
      state(n_times)         {name: array} for a checkpoint (rank 0's)
      restore(s, n)          the same from a checkpoint after step n
      checkpoint_vecs()      {name: Vec} for a checkpoint (saved globally: any rank count restarts)
      restore_vecs(reader)   the same from a checkpoint's reader

    each method optional. The recorder keeps the steps and times itself; ``soil``, ``structure``
    and ``interface`` name the observers the problems read back, and ``add`` appends one (e.g. the
    BEM's divergence guard, ``bem.stability.DivergenceGuard``), which sees every step after the
    recorders and before the progress line."""

    def __init__(self, cfg, comm, what, grid, soil=None, structure=None, interface_keys=(), interface_nodal=(),
                 interface_stride=1):
        self.cfg, self.comm, self.grid = cfg, comm, grid
        self.soil, self.structure = soil, structure
        self.interface = (InterfaceSeries(interface_keys, interface_nodal, interface_stride)
                          if interface_keys else None)
        self.norms = NormHistory()
        self.progress = ProgressLine(cfg, comm, what, grid.n_steps)
        self.steps, self.times = [], []
        self.observers = [o for o in (soil, structure, self.interface, self.norms) if o is not None]
        self.extra = []

    def add(self, observer):
        """Append an observer (it sees each step after the recorders, before the progress line)."""
        self.extra.append(observer)
        return observer

    def add_recorder(self, observer):
        """Append an observer among the recorders: it sees each step with them (``observe``), and
        the steps the time grid writes (``snapshot``) after the structure's and soil's fields;
        its ``state``/``restore`` go into checkpoints."""
        self.observers.append(observer)
        return observer

    def _all(self):
        return self.observers + self.extra + [self.progress]

    @property
    def unorm(self):
        return self.norms.values

    def due(self, n):
        """Whether step n writes fields (the time grid's -ssi_output_stride; 0: never)."""
        return self.grid.writes(n)

    def step(self, n, t, **step):
        """Record step n at time t (``step``: the keys of the protocol above)."""
        self.steps.append(n)
        self.times.append(t)
        for o in self.observers:
            o.observe(n, t, step)
        if self.grid.writes(n):
            for o in self.observers:
                if hasattr(o, "snapshot"):
                    o.snapshot(n, t, step)
        for o in self.extra + [self.progress]:
            o.observe(n, t, step)

    def initial(self, t, write=False, **step):
        """Collective: the state at t = 0 (``step``: the keys of ``step``) to every observer's
        ``initial``; with ``write`` its fields too. Not a step: the steps and times the recorder
        keeps start at step 1."""
        for o in self._all():
            if hasattr(o, "initial"):
                o.initial(t, step, write)

    def checkpoint_vecs(self):
        """Collective: {name: Vec} of every observer's ``checkpoint_vecs``."""
        vecs = {}
        for o in self._all():
            if hasattr(o, "checkpoint_vecs"):
                vecs.update(o.checkpoint_vecs())
        return vecs

    def restore_vecs(self, reader):
        """Collective: every observer's ``restore_vecs`` from a checkpoint's reader."""
        for o in self._all():
            if hasattr(o, "restore_vecs"):
                o.restore_vecs(reader)

    def state(self):
        """Collective: the series so far, for a checkpoint ({name: array}, rank 0's)."""
        s = {"times": np.asarray(self.times, float)}
        for o in self._all():
            if hasattr(o, "state"):
                s.update(o.state(len(self.times)))
        return s

    def restore(self, s, n):
        """The series of a checkpoint after step ``n`` (``state``); the soil's series start at step
        1, one value per step."""
        self.times = [float(t) for t in s["times"]]
        self.steps = list(range(n - len(self.times) + 1, n + 1))
        for o in self._all():
            if hasattr(o, "restore"):
                o.restore(s, n)

    def soil_receivers(self):
        return self.soil.receivers(len(self.times)) if self.soil is not None else None

    def interface_arrays(self):
        return self.interface.arrays() if self.interface is not None else {}
