"""The structure's observer of the recorder (``io.recorder`` protocol): its mesh and fields
(``io.structure.FieldWriter``: displacement, rotation, velocity) and its receiver series
(``io.structure.ReceiverSeries``: displacement, rotation, velocity, acceleration, on rank 0).
Collective unless said otherwise."""
import numpy as np

from ..monitor import event


class StructureRecorder:
    """Collective: the structure's fields (an Output, or None) and receiver series, its output group
    'receivers' (``groups``); ``always``: that group even without receivers (the fixed base's file
    has one; the coupled structure's only with receivers)."""

    def __init__(self, out, model, comm, io_event="SSI_IO", always=False):
        from ..io.structure import FieldWriter, ReceiverSeries
        self.out, self.model, self.comm, self.io_event = out, model, comm, io_event
        self.always = always
        self.fw = FieldWriter(out, model, comm) if out is not None else None
        self.rec = ReceiverSeries(model.dofmap, model.receiver_nodes, comm)

    def initial(self, t, step, write=False):
        if step.get("structure") is not None:
            self.record(t, *step["structure"], write=write)

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

    def groups(self, steps=None, times=None):
        """{'receivers': ``receivers()``} on rank 0 (None elsewhere, and without receivers unless
        ``always``)."""
        keep = self.comm.getRank() == 0 and (self.always or len(self.model.receiver_nodes))
        return {"receivers": self.receivers() if keep else None}

    def receivers(self):
        """Rank 0: the output group of the structure receivers (points, nodes, t, u, rotation, ...)."""
        from ..io.structure import receiver_record
        return receiver_record(self.model, self.rec.all_arrays())
