"""What a run keeps, for the three problem kinds (BEM, FEM, coupled): one recorder.

``Recorder`` holds up to three parts and the run's progress and |u| history:

  SoilRecorder       the soil's mesh and fields in an Output (displacement, nodal
                     traction) and the soil receiver series (a PETSc operator from
                     the nodal field to the receiver points; gathered to rank 0 once,
                     at the end)
  StructureRecorder  the structure's mesh and fields (``io.structure.FieldWriter``:
                     displacement, rotation, velocity) and its receiver series
                     (``io.structure.ReceiverSeries``: displacement, rotation, velocity,
                     acceleration, on rank 0)
  interface series   per-step arrays of the coupling (a dict of lists, rank 0's copy)

Fields are written every -ssi_output_stride steps (``due``); receivers every step. The
problems (bem/problem.py, fem/problem.py, coupling/problem.py) step and hand the
results here; ``step`` also prints the -ssi_monitor progress line and keeps |u| for the
divergence guard. Collective unless said otherwise.
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

    def restore(self, s):
        """The series of a checkpoint: each rank takes its rows of R (and of the resultants')."""
        if self.R is not None:
            full = np.asarray(s["soil_receivers"]).reshape(len(s["times"]), -1)
            r0, r1 = self.R.getOwnershipRange()
            self.series = [row[r0:r1].copy() for row in full]
        if self.res is not None:
            full = np.asarray(s["soil_resultants"]).reshape(len(s["times"]), 6)
            r0, r1 = self.res.R.getOwnershipRange()
            self.res.series = [row[r0:r1].copy() for row in full]

    def resultants(self, times):
        """Collective: the output group 'resultants' (rank 0; None elsewhere or without a
        prescribed region): t, force (K, 3), moment (K, 3) about x_ref, h (the motion's factor at
        t_n), u0, theta0, x_ref."""
        if self.res is None:
            return None
        fm = self.res.arrays()
        if fm is None:
            return None
        m = self.prob.motion
        t = np.asarray(times, float)
        h = np.array([self.prob.disp_factor(int(round(tk / self.prob.dt))) for tk in t])
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
        self.rec = ReceiverSeries(model.layout, model.receiver_nodes, comm)

    def record(self, t, u, v=None, write=False):
        self.rec.record(t, u, v)
        if write:
            self.write(t, u, v)

    def write(self, t, u, v=None):
        """Collective: a snapshot of the fields."""
        if self.fw is not None:
            with event(self.io_event):
                self.fw.write(t, u, v)

    def state(self):
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

    def restore(self, s):
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


class Recorder:
    """Collective: a run's soil and/or structure recorders, its interface series, progress line
    and |u| history (see the module docstring)."""

    def __init__(self, cfg, comm, what, n_steps, soil=None, structure=None, interface_keys=()):
        self.cfg, self.comm = cfg, comm
        self.soil, self.structure = soil, structure
        self.interface = {k: [] for k in interface_keys}
        self.times, self.unorm = [], []
        self.progress = Progress(what, n_steps, enabled=cfg.monitor, every=cfg.monitor_every, comm=comm)

    def due(self, n):
        """Whether step n writes fields (-ssi_output_stride; 0: never)."""
        s = self.cfg.output_stride
        return bool(s) and n % s == 0

    def step(self, n, t, soil=None, structure=None, interface=None, norm=None, status=""):
        """Record step n at time t: ``soil`` (u, p) Vecs, ``structure`` (u, v) Vecs, ``interface``
        a dict with the interface keys; ``norm`` the |u| kept for the guard; ``status`` the
        progress line's tail."""
        self.times.append(t)
        if soil is not None and self.soil is not None:
            self.soil.record(soil[0], soil[1], t)
        if structure is not None and self.structure is not None:
            self.structure.record(t, structure[0], structure[1])
        if interface is not None:
            for k in self.interface:
                self.interface[k].append(interface[k])
        if norm is not None:
            self.unorm.append(norm)
        if self.due(n):               # the series of step n are whole before a snapshot can fail (disk full)
            if soil is not None and self.soil is not None:
                self.soil.write(t, soil[0], soil[1])
            if structure is not None and self.structure is not None:
                self.structure.write(t, structure[0], structure[1])
        self.progress.update(n, status)

    def state(self):
        """Collective: the series so far, for a checkpoint ({name: array}, rank 0's)."""
        s = {"times": np.asarray(self.times, float), "unorm": np.asarray(self.unorm, float)}
        if self.soil is not None:
            s.update(self.soil.state(len(self.times)))
        if self.structure is not None:
            s.update(self.structure.state())
        for k, v in self.interface.items():
            s["interface_" + k] = np.asarray(v)
        return s

    def restore(self, s, n):
        """The series of a checkpoint after step ``n`` (``state``)."""
        self.times = [float(t) for t in s["times"]]
        self.unorm = [float(x) for x in s["unorm"]]
        if self.soil is not None:
            self.soil.restore(s)
        if self.structure is not None:
            self.structure.restore(s)
        for k in self.interface:
            self.interface[k] = list(np.asarray(s["interface_" + k]))
        self.progress.first = n

    def soil_receivers(self):
        return self.soil.receivers(len(self.times)) if self.soil is not None else None

    def interface_arrays(self):
        return {k: np.asarray(v) for k, v in self.interface.items()}
