"""The structure's writers: its mesh and nodal fields in an Output (``FieldWriter``), the series
of its receivers (``ReceiverSeries``) and their output group (``receiver_record``). Collective
unless said otherwise."""
import numpy as np

from ..petsc import init


class ReceiverSeries:
    """Collective: displacement, rotation and velocity of a few nodes every step, on rank 0.

    ``dofmap``: the structure's dof map (``dofmap.DofMap``). Rotations are 0 at nodes
    without them (``has_rotation`` says which). The acceleration at t_n (``all_arrays``) is the
    mean acceleration over the step that ends there, (v^n - v^{n-1}) / dt (0 at t = 0):
    the trapezoidal and midpoint rules' own acceleration of that step, centred half a
    step earlier; a harmonic of frequency f keeps the amplitude factor sin(pi f dt) /
    (pi f dt) (0.96 at f dt = 0.15) and lags by dt/2. (The central difference of the
    velocities would be (a_{n-1} + 2 a_n + a_{n+1}) / 4, amplitude factor cos^2(pi f dt):
    0.79 at f dt = 0.15.)"""

    def __init__(self, dofmap, nodes, comm):
        PETSc = init()
        self.rank = comm.getRank()
        nodes = np.asarray(nodes, np.int64)
        self.n = len(nodes)
        tdofs = dofmap.node_dofs(nodes, 3)
        self.has_rotation = dofmap.has_rotation[nodes]
        rdofs = np.where(self.has_rotation[:, None], tdofs + 3, tdofs)
        template = dofmap.vec()
        idx = np.concatenate([tdofs.ravel(), rdofs.ravel()]) if self.rank == 0 else []
        idx = np.asarray(idx, dtype=PETSc.IntType)
        self.seq = PETSc.Vec().createSeq(len(idx), comm=PETSc.COMM_SELF)
        is_from = PETSc.IS().createGeneral(idx, comm=PETSc.COMM_SELF)
        self.scatter = PETSc.Scatter().create(template, is_from, self.seq, None)
        self.t, self.u, self.r, self.v = [], [], [], []

    def _grab(self, x):
        """Collective: (2, n, 3) translations and rotations on rank 0 (None elsewhere)."""
        self.scatter.scatter(x, self.seq)
        if self.rank != 0:
            return None
        a = self.seq.getArray(readonly=True).reshape(2, self.n, 3).copy()
        a[1][~self.has_rotation] = 0.0
        return a

    def record(self, t, u, v=None):
        """Collective: the values of step t (u, and the velocity Vec ``v`` when given)."""
        au = self._grab(u)
        av = self._grab(v) if v is not None else None
        if self.rank == 0:
            self.t.append(t)
            self.u.append(au[0])
            self.r.append(au[1])
            if av is not None:
                self.v.append(av[0])

    def arrays(self):
        return np.asarray(self.t), np.asarray(self.u).reshape(len(self.t), self.n, 3)

    def all_arrays(self):
        """Rank 0: {t, u, rotation, velocity, acceleration} (velocity/acceleration when recorded)."""
        t, u = self.arrays()
        out = {"t": t, "u": u, "rotation": np.asarray(self.r).reshape(len(t), self.n, 3),
               "has_rotation": self.has_rotation}
        if len(self.v) == len(t) and len(t) > 1:
            v = np.asarray(self.v).reshape(len(t), self.n, 3)
            out["velocity"] = v
            a = np.zeros_like(v)
            a[1:] = (v[1:] - v[:-1]) / (t[1:] - t[:-1])[:, None, None]
            out["acceleration"] = a
        return out


def structure_topology(mesh):
    """(cell type, cells) for ``Output.write_mesh``: 'hex8' and the bricks for a brick-only
    mesh (as before parts existed), else 'mixed' and [(XDMF type, cells)] of every block."""
    if all(b.element.name == "hex8" for b in mesh.blocks):
        return "hex8", mesh.cells
    return "mixed", [(b.element.xdmf_type, b.cells) for b in mesh.blocks]


class FieldWriter:
    """Collective: the structure's mesh and nodal fields in an Output: displacement (and
    rotation where the model has rotations) of a dof-layout Vec, and the velocity. A
    brick-only model writes its dof-layout Vecs directly (dof = 3 * node + c)."""

    def __init__(self, out, model, comm):
        self.out, self.dm = out, model.dofmap
        self.rot = bool(self.dm.has_rotation.any())
        ctype, cells = structure_topology(model.mesh)
        cvec = model.coords_vec() if not self.rot else self.dm.nodal_coords(model.mesh.coords)
        out.write_mesh(cvec, cells if comm.getRank() == 0 else None, ctype)
        if self.rot:
            self.bu, self.br, self.bv = self.dm.node_vec(), self.dm.node_vec(), self.dm.node_vec()

    def write(self, t, u, v=None, names=("displacement", "rotation", "velocity")):
        if not self.rot:
            fields = {names[0]: u}
            if v is not None:
                fields[names[2]] = v
        else:
            fields = {names[0]: self.dm.extract(u, self.bu, 0), names[1]: self.dm.extract(u, self.br, 1)}
            if v is not None:
                fields[names[2]] = self.dm.extract(v, self.bv, 0)
        self.out.write_fields(t, fields)


def receiver_record(model, rec_arrays):
    """Rank 0: the structure receivers' group of an output file."""
    d = {"points": model.receivers.reshape(-1, 3), "nodes": model.receiver_nodes,
         "node_points": model.mesh.coords[model.receiver_nodes].reshape(-1, 3),
         "snap_distance": model.receiver_dist}
    d.update(rec_arrays)
    return d
