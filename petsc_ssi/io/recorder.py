"""What a run keeps, for the three problem kinds (BEM, FEM, coupled): one recorder, a list of
observers with one small protocol (``Recorder``; PyLith's observers):

  SoilRecorder       the soil's mesh and fields in an Output (displacement, nodal
                     traction) and the soil receiver series (a PETSc operator from
                     the nodal field to the receiver points; gathered to rank 0 once,
                     at the end)
  StructureRecorder  the structure's mesh and fields (``io.structure.FieldWriter``:
                     displacement, rotation, velocity) and its receiver series
                     (``io.structure.ReceiverSeries``: displacement, rotation, velocity,
                     acceleration, on rank 0)
  InterfaceSeries    per-step arrays of the coupling (a dict of lists, rank 0's copy)
  NormHistory        |u| of every step; ProgressLine the -ssi_monitor line

A problem hands each step to ``Recorder.step``; fields are written on the steps its time
grid says (``TimeGrid.writes``: every -ssi_output_stride steps), receivers every step. A new
output is a new observer. Collective unless said otherwise.
"""
import numpy as np

from ..monitor import Progress, event


class SoilRecorder:
    """Collective: the soil's fields and receiver series. ``out``: an Output (or None: receivers
    only); ``prob``: the BEM problem (bem/halfspace.py HalfSpace); ``march``: its Marcher."""

    def __init__(self, out, comm, prob, march):
        from ..bem import receivers as bem_rec
        from ..bem.receivers import traction_to_nodes
        self.out, self.comm, self.prob = out, comm, prob
        if out is not None:
            cvec = march.u_tmpl.duplicate()
            r0, r1 = cvec.getOwnershipRange()
            cvec.setArray(prob.mesh.nodes.reshape(-1)[r0:r1])
            out.write_mesh(cvec, prob.mesh.cells if comm.getRank() == 0 else None, "quad9")
        self.R = None
        if len(prob.receivers):
            self.R, _ = bem_rec.operator(comm, prob.mesh, prob.receivers, prob.planes, march.u_tmpl.getLocalSize())
            self.y = self.R.createVecLeft()
        self.tnode = traction_to_nodes(comm, prob, march)
        self.tfield = march.u_tmpl.duplicate()
        self.series = []
        self.res = None                   # the prescribed region's force and moment (bem/resultants.py)
        if prob.regions.n_disp and getattr(prob, "motion", None) is not None:
            from ..bem.resultants import Resultants
            self.res = Resultants(comm, prob, march.p_tmpl)

    def observe(self, n, t, step):
        if step.get("soil") is not None:
            self.record(*step["soil"], t)

    def snapshot(self, n, t, step):
        if step.get("soil") is not None:
            self.write(t, *step["soil"])

    def record(self, u, p, t=None, write=False):
        if self.R is not None:
            self.R.mult(u, self.y)
            self.series.append(self.y.getArray().copy())
        if self.res is not None:
            self.res.record(p)
        if write:
            self.write(t, u, p)

    def write(self, t, u, p):
        """Collective: a snapshot of the fields (displacement, nodal traction)."""
        if self.out is not None:
            with event("SSI_IO"):
                if self.tnode is not None:
                    self.tnode.mult(p, self.tfield)
                self.out.write_fields(t, {"displacement": u, "traction": self.tfield})

    def state(self, n_times):
        """Collective: {'soil_receivers': (K, R, 3), 'soil_resultants': (K, 6)} on rank 0, for a
        checkpoint."""
        out = {}
        u = self.receivers(n_times)
        if u is not None:
            out["soil_receivers"] = u
        if self.res is not None:
            fm = self.res.arrays()
            if fm is not None:
                out["soil_resultants"] = fm
        return out

    def restore(self, s, n=None):
        """The series of a checkpoint: each rank takes its rows of R (and of the resultants')."""
        if self.R is not None:
            full = np.asarray(s["soil_receivers"]).reshape(len(s["times"]), -1)
            r0, r1 = self.R.getOwnershipRange()
            self.series = [row[r0:r1].copy() for row in full]
        if self.res is not None:
            full = np.asarray(s["soil_resultants"]).reshape(len(s["times"]), 6)
            r0, r1 = self.res.R.getOwnershipRange()
            self.res.series = [row[r0:r1].copy() for row in full]

    def resultants(self, steps, times):
        """Collective: the output group 'resultants' (rank 0; None elsewhere or without a
        prescribed region) of the recorded ``steps`` at ``times``: t, force (K, 3), moment (K, 3)
        about x_ref, h (the motion's factor at t_n), u0, theta0, x_ref."""
        if self.res is None:
            return None
        fm = self.res.arrays()
        if fm is None:
            return None
        m = self.prob.motion
        t = np.asarray(times, float)
        h = np.array([self.prob.disp_factor(n) for n in steps])
        return {"t": t, "force": fm[:, :3], "moment": fm[:, 3:], "h": h, "u0": m.u0, "theta0": m.theta,
                "x_ref": m.xref}

    def receivers(self, n_times):
        """Collective: the receiver series (K, R, 3) on rank 0 (None elsewhere, or without receivers)."""
        if self.R is None:
            return None
        loc = np.array(self.series).reshape(n_times, -1)
        allp = self.comm.tompi4py().gather(loc, root=0)
        if self.comm.getRank() == 0:
            return np.concatenate(allp, axis=1).reshape(n_times, len(self.prob.receivers), 3)
        return None


class StructureRecorder:
    """Collective: the structure's fields (an Output, or None) and receiver series."""

    def __init__(self, out, model, comm, io_event="SSI_IO"):
        from .structure import FieldWriter, ReceiverSeries
        self.out, self.model, self.comm, self.io_event = out, model, comm, io_event
        self.fw = FieldWriter(out, model, comm) if out is not None else None
        self.rec = ReceiverSeries(model.dofmap, model.receiver_nodes, comm)

    def observe(self, n, t, step):
        if step.get("structure") is not None:
            self.record(t, *step["structure"])

    def snapshot(self, n, t, step):
        if step.get("structure") is not None:
            self.write(t, *step["structure"])

    def record(self, t, u, v=None, write=False):
        self.rec.record(t, u, v)
        if write:
            self.write(t, u, v)

    def write(self, t, u, v=None):
        """Collective: a snapshot of the fields."""
        if self.fw is not None:
            with event(self.io_event):
                self.fw.write(t, u, v)

    def state(self, n_times=None):
        """Rank 0: the receiver series, for a checkpoint."""
        r = self.rec
        if self.comm.getRank() != 0:
            return {}
        K = len(r.t)
        s = {"structure_t": np.asarray(r.t, float), "structure_u": np.asarray(r.u).reshape(K, r.n, 3),
             "structure_r": np.asarray(r.r).reshape(K, r.n, 3)}
        if len(r.v) == K:
            s["structure_v"] = np.asarray(r.v).reshape(K, r.n, 3)
        return s

    def restore(self, s, n=None):
        r = self.rec
        if self.comm.getRank() != 0:
            return
        r.t = [float(t) for t in s["structure_t"]]
        r.u = [a.copy() for a in s["structure_u"]]
        r.r = [a.copy() for a in s["structure_r"]]
        r.v = [a.copy() for a in s["structure_v"]] if "structure_v" in s else []

    def receivers(self):
        """Rank 0: the output group of the structure receivers (points, nodes, t, u, rotation, ...)."""
        from .structure import receiver_record
        return receiver_record(self.model, self.rec.all_arrays())


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

      observe(n, t, step)    step n at time t; ``step`` holds what the problem gives: 'soil' (u, p)
                             Vecs, 'structure' (u, v) Vecs, 'interface' (a dict), 'norm', 'status'
      snapshot(n, t, step)   the fields of a step the time grid writes (``TimeGrid.writes``),
                             after every observer saw the step (the series are whole before a
                             snapshot can fail on a full disk)
      state(n_times)         {name: array} for a checkpoint (rank 0's)
      restore(s, n)          the same from a checkpoint after step n

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
