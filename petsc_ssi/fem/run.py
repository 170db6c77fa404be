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
from ..monitor import Progress, event
from ..io.output import Output, provenance
from .integrators import make_integrator, green_constants
from .loads import history_from
from .model import build_model
from .options import alpha_m


class ReceiverSeries:
    """Collective: the displacement of a few nodes every step, on rank 0."""

    def __init__(self, template, nodes, comm):
        PETSc = init()
        self.rank = comm.getRank()
        idx = (3 * np.asarray(nodes, np.int64)[:, None] + np.arange(3)).ravel() if self.rank == 0 else []
        idx = np.asarray(idx, dtype=PETSc.IntType)
        self.n = len(nodes)
        self.seq = PETSc.Vec().createSeq(len(idx), comm=PETSc.COMM_SELF)
        is_from = PETSc.IS().createGeneral(idx, comm=PETSc.COMM_SELF)
        self.scatter = PETSc.Scatter().create(template, is_from, self.seq, None)
        self.t, self.u = [], []

    def record(self, t, u):
        self.scatter.scatter(u, self.seq)
        if self.rank == 0:
            self.t.append(t)
            self.u.append(self.seq.getArray(readonly=True).reshape(self.n, 3).copy())

    def arrays(self):
        return np.asarray(self.t), np.asarray(self.u).reshape(len(self.t), self.n, 3)


def _history(cfg, comm):
    """Collective: the load history (the option checks read it once already)."""
    err, hist = None, None
    try:
        hist = history_from(cfg)
    except SSIError as exc:
        err = f"-ssi_fem_load_history {cfg.fem_load_history}: {exc}"
    collective_error(err, comm)
    return hist


def make_model_integrator(cfg, comm, model=None):
    """Collective: (model, integrator, alpha_m) for the options ``cfg``."""
    model = model or build_model(cfg, comm)
    am, note = alpha_m(cfg)
    printf(f"[fem] {note}; integrator {cfg.fem_integrator}, solver {cfg.fem_solver}")
    coords = model.coords_vec() if cfg.fem_solver == "iterative" else None
    integ = make_integrator(cfg.fem_integrator, model.K, model.m, cfg.dt, am, model.fixed,
                            cfg.fem_newmark_alpha, cfg.fem_newmark_delta, solver=cfg.fem_solver,
                            coords_vec=coords)
    return model, integ, am


def run_fem(cfg):
    """Collective: run the case; returns a summary dict (receiver series on rank 0)."""
    PETSc = init()
    comm = PETSc.COMM_WORLD
    hist = _history(cfg, comm)                     # before assembly and factorisation
    model, integ, am = make_model_integrator(cfg, comm)
    n_steps = int(round(cfg.t_end / cfg.dt))
    F, fn = model.load_vec(), model.load_vec()
    out = _open_output(cfg, model, comm)
    rec = ReceiverSeries(integ.u, model.receiver_nodes, comm)
    vel = integ.u.duplicate()

    def sample(n):
        F.copy(fn)
        fn.scale(hist.cell_mean(n, cfg.dt))
        return fn

    integ.start(f0=sample(0))
    _record(cfg, out, rec, integ, vel, 0)
    prog = Progress("FEM time loop", n_steps, cfg.monitor, cfg.monitor_every, comm)
    with event("FEM_timeloop"):
        for n in range(1, n_steps + 1):
            integ.step(sample(n))
            _record(cfg, out, rec, integ, vel, n)
            prog.update(n, f"t = {n * cfg.dt:.5g} s")
    t, u = rec.arrays()
    _close_output(cfg, out, model, rec, comm, am, n_steps, integ)
    if comm.getRank() == 0 and len(model.receiver_nodes):
        printf(f"[fem] receiver 0 at t = {t[-1]:.5g} s: u = ({u[-1, 0, 0]:.6e}, {u[-1, 0, 1]:.6e}, "
               f"{u[-1, 0, 2]:.6e}) m")
    integ.destroy()
    return {"t": t, "u": u, "n_steps": n_steps, "alpha_m": am, "model": model}


def _open_output(cfg, model, comm):
    if not cfg.output:
        return None
    with event("FEM_io"):
        out = Output(cfg.output, comm)
        out.write_mesh(model.coords_vec(), model.mesh.cells if comm.getRank() == 0 else None, "hex8")
    return out


def _record(cfg, out, rec, integ, vel, n):
    rec.record(n * cfg.dt, integ.u)
    if out is not None and cfg.output_stride > 0 and n % cfg.output_stride == 0:
        with event("FEM_io"):
            out.write_fields(n * cfg.dt, {"displacement": integ.u, "velocity": integ.velocity(vel)})


def _close_output(cfg, out, model, rec, comm, am, n_steps, integ):
    if out is None:
        return
    t, u = rec.arrays()
    receivers = None
    if comm.getRank() == 0:
        receivers = {"points": model.receivers.reshape(-1, 3), "nodes": model.receiver_nodes,
                     "node_points": model.mesh.coords[model.receiver_nodes].reshape(-1, 3),
                     "snap_distance": model.receiver_dist, "t": t, "u": u}
    extra = {"fem": {"alpha_m": am, "n_steps": n_steps, "n_nodes": model.mesh.n_nodes,
                     "n_cells": model.mesh.n_cells, "mesh": model.mesh.source,
                     "receiver_snap_distance": [float(d) for d in model.receiver_dist]}}
    if cfg.fem_integrator == "green":
        extra["fem"]["b"] = green_constants(cfg.dt, am, cfg.fem_newmark_alpha, cfg.fem_newmark_delta)
    with event("FEM_io"):
        out.close(receivers=receivers, attrs={"problem": "fem", "alpha_m": am, "dt": cfg.dt},
                  record=provenance(cfg, comm, extra))
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
