"""What a run keeps, for the three problem kinds (BEM, FEM, coupled): one recorder, a list of
observers with one small protocol (``Recorder``; PyLith's observers). The observers of a domain
live beside it (issue 40: ``io/`` holds files, formats and the recorder, and imports neither
``bem/`` nor ``fem/``):

  bem.recorder.SoilRecorder       the soil's mesh, fields and receiver series; groups 'receivers',
                                  'resultants' (a prescribed region's force and moment)
  bem.input_motion.MasslessFooting  a massless footing's motion; group 'input_motion'
  fem.recorder.StructureRecorder  the structure's mesh, fields and receiver series; group 'receivers'
  fem.forces.ForceRecorder        member forces (its group 'forces' of virtual datasets is written
                                  through the Output's call-backs, ``write_serial``)
  fem.demands.Demands             base shear, overturning moment, drifts; group 'demands'
  InterfaceSeries    per-step arrays of the coupling (a dict of lists, rank 0's copy); group
                     'interface' (``coupling.problem.InterfaceRecord`` lays it out)
  StepClock          the wall time of every step; group 'timing' when asked for
  NormHistory        |u| of every step; ProgressLine the -ssi_monitor line

A problem hands each step to ``Recorder.step``; fields are written on the steps its time
grid says (``TimeGrid.writes``: every -ssi_output_stride steps), receivers every step. At the
end (and at each flush) the problem asks the recorder for the groups of each of its outputs
(``Recorder.groups(out)``) and gives them to ``Output.close``/``flush``: each observer says the
groups it writes. A new output is a new observer: a class with the protocol's methods (those it
needs), added with ``Recorder.add`` or ``add_recorder`` (``out``: the Output its groups go to,
unless it has its own ``out``). Collective unless said otherwise.
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

    def groups(self, steps, times):
        """{'interface': the series as arrays with the steps' times 't'} (a subclass lays them out:
        ``coupling.problem.InterfaceRecord``)."""
        return {"interface": dict(self.arrays(), t=np.asarray(times, float))}

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
    this one's, on this rank): what a long record's per-step cost is, and whether it stays flat.
    ``group``: written as the output group 'timing' (dataset step_wall [s])."""

    def __init__(self, group=False):
        import time
        self._now = time.perf_counter
        self.last = None
        self.values = []
        self.group = bool(group)

    def groups(self, steps, times):
        return {"timing": {"step_wall": (np.asarray(self.values, float), "s")}} if self.group else {}

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
      groups(steps, times)   the output groups it writes, {group: {dataset: array, (array, unit) or
                             (array, unit, {attribute: value})}} (``Output.close``), of the recorded
                             ``steps`` at ``times``; the group 'receivers' is the file's receivers.
                             Collective (it may gather); the data is rank 0's (Output writes rank
                             0's), a group None where a rank has none

    each method optional. The recorder keeps the steps and times itself; ``soil``, ``structure``
    and ``interface`` name the observers the problems read back, and ``add`` appends one (e.g. the
    BEM's divergence guard, ``bem.stability.DivergenceGuard``), which sees every step after the
    recorders and before the progress line. An observer's groups go to its ``out`` (the Output of
    its fields), or to the one given to ``add``/``add_recorder``; the interface series' to the
    soil's. ``interface``: the coupling's series (an ``InterfaceSeries``), else one of
    ``interface_keys`` when given."""

    def __init__(self, cfg, comm, what, grid, soil=None, structure=None, interface_keys=(), interface_nodal=(),
                 interface_stride=1, interface=None):
        self.cfg, self.comm, self.grid = cfg, comm, grid
        self.soil, self.structure = soil, structure
        self.interface = interface if interface is not None else (
            InterfaceSeries(interface_keys, interface_nodal, interface_stride) if interface_keys else None)
        self.norms = NormHistory()
        self.progress = ProgressLine(cfg, comm, what, grid.n_steps)
        self.steps, self.times = [], []
        self.observers = [o for o in (soil, structure, self.interface, self.norms) if o is not None]
        self.extra = []
        self._outs = {}                       # id(observer) -> the Output its groups go to
        if self.interface is not None:
            self._outs[id(self.interface)] = getattr(soil, "out", None)

    def add(self, observer, out=None):
        """Append an observer (it sees each step after the recorders, before the progress line);
        ``out``: the Output its groups go to (else its own ``out``)."""
        self.extra.append(observer)
        if out is not None:
            self._outs[id(observer)] = out
        return observer

    def add_recorder(self, observer, out=None):
        """Append an observer among the recorders: it sees each step with them (``observe``), and
        the steps the time grid writes (``snapshot``) after the structure's and soil's fields;
        its ``state``/``restore`` go into checkpoints; ``out`` as for ``add``."""
        self.observers.append(observer)
        if out is not None:
            self._outs[id(observer)] = out
        return observer

    def output_of(self, observer):
        """The Output ``observer``'s groups go to (None: none)."""
        return self._outs.get(id(observer), getattr(observer, "out", None))

    def groups(self, out):
        """Collective: {group: data} of every observer whose output is ``out`` (``groups`` of the
        protocol; the groups a rank does not hold, None, left out), in the observers' order."""
        found = {}
        for o in self._all():
            if hasattr(o, "groups") and self.output_of(o) is out:
                for name, data in o.groups(self.steps, self.times).items():
                    if data is not None:
                        found[name] = data
        return found

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

