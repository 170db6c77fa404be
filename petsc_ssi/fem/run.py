"""``-ssi_problem fem``: the structure alone, time-stepped (paper Section 3).

Collective. Steps: the load history (already read and checked with the
options, before any heavy work), build the model (mesh, checks, K, M), alpha_m, the
integrator (D factorised once), then for n = 1..N: u^n (eq. 13), the load
sample f^n (mean of f over [t_n - dt/2, t_n + dt/2]) as a velocity impulse
(eqs. 14, 16); displacement and velocity every -ssi_output_stride steps, the
receiver series every step. PETSc log events: FEM_assembly, FEM_factor,
FEM_timeloop, FEM_io.
"""
import os

import numpy as np

from ..petsc import init, SSIError, collective_error, printf
from ..monitor import event
from ..io.output import provenance
from .integrators import make_integrator, green_constants
from .loads import history_from
from .model import build_model
from .options import alpha_m


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


def load_history(cfg, comm):
    """Collective: the load history (the option checks read it once already)."""
    err, hist = None, None
    try:
        hist = history_from(cfg)
    except SSIError as exc:
        err = f"-ssi_fem_load_history {cfg.fem_load_history}: {exc}"
    collective_error(err, comm)
    return hist


def near_null_args(solver, model):
    """(coords_vec, near_null) for make_solver: none for a direct solver; PETSc's rigid-body
    modes of the coordinates for a brick-only model; the dof map's six modes otherwise."""
    if solver != "iterative":
        return None, None
    if model.layout.uniform3:
        return model.coords_vec(), None
    return None, model.layout.near_null_space(model.mesh.coords)


def make_model_integrator(cfg, comm, model=None):
    """Collective: (model, integrator, alpha_m) for the options ``cfg``."""
    model = model or build_model(cfg, comm)
    am, note = alpha_m(cfg)
    printf(f"[fem] {note}; integrator {cfg.fem_integrator}, solver {cfg.fem_solver}")
    coords, near = near_null_args(cfg.fem_solver, model)
    integ = make_integrator(cfg.fem_integrator, model.K, model.m, cfg.dt, am, model.fixed,
                            cfg.fem_newmark_alpha, cfg.fem_newmark_delta, solver=cfg.fem_solver,
                            coords_vec=coords, near_null=near)
    return model, integ, am


def run_fem(cfg, comm=None):
    """Collective: run the case (``problem.FEMTransient``); returns a summary dict (receiver series
    on rank 0)."""
    from .problem import FEMTransient
    return FEMTransient(cfg, comm).run()


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
        self.out, self.dm = out, model.layout
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


def _close_output(cfg, out, model, srec, comm, am, n_steps, integ, status="completed", final=True):
    """Collective: receivers, attributes and run record into the output; ``final``: close it
    (else flush it: readable, still open)."""
    if out is None:
        return
    t, u = srec.rec.arrays()
    receivers = srec.receivers() if comm.getRank() == 0 else None
    extra = {"fem": {"alpha_m": am, "n_steps": n_steps, "n_nodes": model.mesh.n_nodes,
                     "n_cells": model.mesh.n_cells, "n_dofs": model.layout.size, "mesh": model.mesh.source,
                     "elements": model.mesh.element_counts(),
                     "receiver_snap_distance": [float(d) for d in model.receiver_dist]}}
    if cfg.fem_integrator == "green":
        extra["fem"]["b"] = green_constants(cfg.dt, am, cfg.fem_newmark_alpha, cfg.fem_newmark_delta)
    with event("FEM_io"):
        (out.close if final else out.flush)(receivers=receivers, attrs={"problem": "fem", "alpha_m": am, "dt": cfg.dt},
                                            record=provenance(cfg, comm, extra), status=status)
    if not final:
        return
    if cfg.plot and comm.getRank() == 0 and len(model.receiver_nodes):
        _plot(cfg.output, t, u)
    printf(f"[fem] wrote {cfg.output} (+ .xmf, .json)")


def _plot(path, t, u):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(3, 1, sharex=True, figsize=(7, 7))
    for i, ax in enumerate(axs):
        ax.plot(t, u[:, :, i])
        ax.set_ylabel(f"u_{'xyz'[i]} [m]")
    axs[-1].set_xlabel("t [s]")
    fig.tight_layout()
    fig.savefig(os.path.splitext(path)[0] + ".png", dpi=120)
    plt.close(fig)
