"""The soil's observer of the recorder (``io.recorder`` protocol): its mesh and fields in an Output
(displacement, nodal traction), the soil receiver series (a PETSc operator from the nodal field to
the receiver points; gathered to rank 0 once, at the end) and a prescribed region's resultants;
its output groups 'receivers' and 'resultants' (``groups``). Collective unless said otherwise."""
import numpy as np

from ..monitor import event


def at_rest(prob, march, t, out):
    """Collective: the soil's (u, p) at rest at time t (t = 0): u the total field, the free field's
    at t with a seismic input (``out`` holds it), p zero."""
    u0, p0 = march.u_tmpl.duplicate(), march.p_tmpl.duplicate()
    u0.zeroEntries()
    p0.zeroEntries()
    return prob.total_field(u0, t, out), p0


class SoilRecorder:
    """Collective: the soil's fields and receiver series. ``out``: an Output (or None: receivers
    only); ``prob``: the BEM problem (bem/halfspace.py HalfSpace); ``march``: its Marcher."""

    def __init__(self, out, comm, prob, march):
        from . import receivers as bem_rec
        from .receivers import traction_to_nodes
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
            from .resultants import Resultants
            self.res = Resultants(comm, prob, march.p_tmpl)

    def initial(self, t, step, write=False):
        """The fields at t = 0 (the soil at rest, with a seismic input its free field), when the
        time grid writes step 0: the XDMF's first frame. The receiver series start at step 1."""
        if write and step.get("soil") is not None:
            self.write(t, *step["soil"])

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

    def groups(self, steps, times):
        """Collective: the output groups 'receivers' (points, t, u) and 'resultants' (``resultants``),
        rank 0's (None elsewhere, or without receivers or a prescribed region)."""
        u = self.receivers(len(times))
        recd = {"points": self.prob.receivers, "t": np.asarray(times), "u": u} if u is not None else None
        return {"receivers": recd, "resultants": self.resultants(steps, times)}

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
        loc = np.array(self.series).reshape(n_times, -1) if n_times else np.zeros((0, 0))   # (a stop at step 1)
        allp = self.comm.tompi4py().gather(loc, root=0)
        if self.comm.getRank() == 0:
            return np.concatenate(allp, axis=1).reshape(n_times, len(self.prob.receivers), 3)
        return None
