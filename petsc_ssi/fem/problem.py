"""``FEMTransient``: the structure alone (-ssi_problem fem), time-stepped (paper Section 3).

Collective. Steps: the load history (already read and checked with the options, before any heavy
work), build the model (mesh, checks, K, M), alpha_m, the integrator (D factorised once), then for
n = 1..N: u^n (eq. 13), the load sample f^n (mean of f over [t_n - dt/2, t_n + dt/2]) as a
velocity impulse (eqs. 14, 16); displacement and velocity every -ssi_output_stride steps, the
receiver series every step. PETSc log events: FEM_assembly, FEM_factor, FEM_timeloop, FEM_io.

The stages of ``petsc_ssi.problem.TransientProblem``: the constructor reads the load history,
the parts and the mesh and checks every input (``model.build_model`` without assembly);
``setup`` assembles K and M and factorises D (``integrators.make_model_integrator``); ``start`` takes the
initial impulse of the load and records t = 0; ``step`` is one step of the integrator (paper eqs.
13-16) with the load sample f^n; ``finish`` writes receivers and sidecars. ``state`` between
steps: (u, v), displacement and velocity in the dof map's layout.
"""
import os

import numpy as np

from ..petsc import printf, SSIError
from ..monitor import event, staged
from ..io.output import Output, provenance
from .forces import add_force_recorder
from ..problem import TransientProblem
from .. import timegrid
from . import options as _options  # noqa: F401  (declares the structure's -ssi_fem_ options)
from .model import build_model
from .loads import load_history
from ..sources.nodal import NodalLoad
from .integrators import make_model_integrator, green_constants


class FEMTransient(TransientProblem):
    kind = "fem"

    def __init__(self, cfg, comm=None):
        super().__init__(cfg, comm)
        self.check_output()
        with staged("FEM setup"):
            self.hist = load_history(cfg, self.comm)          # before assembly and factorisation
            self.model = build_model(cfg, self.comm, assemble_matrices=False)
            from .demands import DemandSpec
            from ..petsc import collective
            with collective(self.comm, "checking the storey demands' options"):
                self.demand_spec = DemandSpec(cfg, self.model, "-ssi_receivers", base="reactions")
            self.support = None
            if cfg.get("seismic", "none") != "none":        # a fixed base moving with the record
                from ..seismic.input import SupportMotion
                self.support = SupportMotion(cfg, self.comm, scheme=cfg.fem_integrator)
                self._check_supported_axes()
        # without -ssi_t_end a run under a record lasts the record (nothing is written into the options)
        self.grid = timegrid.TimeGrid.of_run(cfg, [self.support.duration] if self.support is not None else [])
        if self.support is not None:
            from ..seismic.input import report
            report(self.support, self.grid.t_end, self.comm,
                   "the start and any high-pass pad, see the support motion lines")
        self.integ = self.rec = self.out = self.forces = self.demands = self.gravity = None
        self.state = None
        self.check_disk()

    def _check_supported_axes(self):
        """SSIError (every rank: the fixed dofs are replicated) unless every axis the support motion
        drives has a fixed translation along it: the ground moves the structure only through its
        supports, so a structure with none along an axis floats on it and the relative-motion
        form's answer along that axis (-M iota a_g on free masses) is a rigid drift, not a response."""
        dm = self.model.dofmap
        tdofs = dm.translation_dofs(np.arange(self.model.mesh.n_nodes))
        fixed = np.asarray(self.model.fixed, np.int64)
        loose = [a for k, a in enumerate("xyz") if a in self.support.motions and not np.isin(tdofs[:, k], fixed).any()]
        if loose:
            raise SSIError(f"-ssi_seismic vertical drives {', '.join(loose)} but no translation along "
                           f"{' or '.join(loose)} is fixed (-ssi_fem_fixed {self.cfg.get('fem_fixed') or '(none)'}): the "
                           f"base moves the structure only through its supports, so it would float; fix the base "
                           f"along {', '.join(loose)} (e.g. -ssi_fem_fixed base) or leave those records out")

    def output_bytes(self):
        return structure_bytes(self.model, self.grid)

    def setup(self):
        self._advance("created", "set up")
        with staged("FEM assembly"):
            self.model.assemble()
            _, self.integ, self.am = make_model_integrator(self.cfg, self.comm, self.grid.dt, self.model)
        self.fn = self.model.load_vec()
        self.load_source = NodalLoad(self.model.load_vec(), self.hist)      # F a(t) (sources/nodal.py)
        self.vel = self.integ.u.duplicate()
        self.inertia = self._inertia() if self.support is not None else {}
        from .gravity import gravity_case               # -ssi_fem_gravity: the static self-weight case
        with staged("FEM gravity"):
            self.gravity = gravity_case(self.cfg, self.model, self.comm,
                                        ref=self.demand_spec.ref if self.demand_spec.has_base else None)

    def _inertia(self):
        """{axis: -M iota_axis}: the effective earthquake load per unit ground acceleration along
        each axis of the support motion (lumped masses of the translation dofs) [N / (m/s^2)]; none
        on the fixed dofs (they move with the ground: their inertia goes to the supports, and the
        integrator would drop it with a warning that a load acts on fixed dofs)."""
        dm, out = self.model.dofmap, {}
        tdofs = dm.translation_dofs(np.arange(self.model.mesh.n_nodes))
        tdofs = np.where(np.isin(tdofs, np.asarray(self.model.fixed, np.int64)), -1, tdofs)
        r0, r1 = self.model.m.getOwnershipRange()
        for k, axis in enumerate("xyz"):
            if axis not in self.support.motions:
                continue
            iota = np.zeros(r1 - r0)
            d = tdofs[:, k]
            d = d[(d >= r0) & (d < r1)] - r0
            iota[d] = 1.0
            v = self.model.m.duplicate()
            v.getArray()[:] = -self.model.m.getArray(readonly=True) * iota
            out[axis] = v
        return out

    @property
    def F(self):
        """The structure's spatial load Vec (the load source's F, after ``setup``): a script may
        change it between steps."""
        return self.load_source.F

    def load(self, n):
        """The load sample of step n: the spatial load times the mean of the history over the
        step's cell [t_n - dt/2, t_n + dt/2]; with a support motion also -M iota times the mean
        ground acceleration over the same cell (exact for the piecewise-linear record)."""
        self.load_source.sample(self.fn, n, self.grid.dt, "cell")
        t, h = self.time(n), 0.5 * self.grid.dt
        for axis, v in self.inertia.items():
            self.fn.axpy(float(self.support.mean_acceleration(axis, t - h, t + h)), v)
        return self.fn

    def ground_acceleration(self, times):
        """(K, 3) the ground's mean acceleration over the step that ends at each time (the recorded
        relative acceleration's own convention, ``io.structure.ReceiverSeries``; 0 at t = 0)."""
        t = np.asarray(times, float)
        out = np.zeros((len(t), 3))
        for k, axis in enumerate("xyz"):
            out[1:, k] = self.support.mean_acceleration(axis, t[1:] - self.grid.dt, t[1:])
        return out

    def start(self):
        self._advance("set up", "started")
        from ..io.recorder import Recorder
        from .recorder import StructureRecorder
        cfg, comm = self.cfg, self.comm
        rd = self._open_restart()
        with event("FEM_io"):
            self.out = (Output(cfg.output, comm, resume=rd.output_state("out") if rd else None, run_id=self.run_id)
                        if cfg.output else None)
            self.rec = Recorder(cfg, comm, "FEM time loop", self.grid,
                                structure=StructureRecorder(self.out, self.model, comm, io_event="FEM_io",
                                                            always=True))
            self.forces = add_force_recorder(cfg, self.out, self.model, comm, self.rec)
            if self.forces is not None and self.gravity is not None:
                self.forces.set_gravity(self.gravity.u)      # G, and the signed extremes of E(t) from t = 0
        if self.demand_spec.any:                  # base shear, overturning moment, drifts (fem/demands.py)
            from .demands import Demands
            sup = self.support                    # the base moves with the ground: its inertia m a_g
            ground = (lambda t: np.array([float(sup.acceleration(a, t)) for a in "xyz"])) if sup is not None else None
            self.demands = self.rec.add(Demands(self.demand_spec, self.model, comm, "[fem]", ground=ground,
                                                a1=self.integ.a1), out=self.out)
        self.integ.start(f0=self.load(0))
        if rd is None:                            # the records of t = 0 (series, fields, forces, demands)
            self.rec.initial(self.time(0), write=self.grid.writes(0),
                             structure=(self.integ.u, self.integ.velocity(self.vel)))
        self._resume()
        self.state = (self.integ.u, self.vel)

    def checkpoint_state(self):
        serial = self.rec.state()
        serial.update(self._output_state("out", self.out))
        serial.update(self.integ.checkpoint_scalars())
        vecs = self.integ.checkpoint_vecs()
        vecs.update(self.rec.checkpoint_vecs())           # the observers' (member force envelopes)
        return vecs, serial

    def restore_state(self, reader):
        self.integ.restore(reader)
        self.rec.restore_vecs(reader)
        self.rec.restore(reader.serial, int(self.restart["step"]))

    def step(self, n):
        self._check_step(n)
        with staged("FEM time loop"), event("FEM_timeloop"):
            self.integ.step(self.load(n))
            t = self.time(n)
            self.n = n                        # the step is taken; its records follow
            self.rec.step(n, t, structure=(self.integ.u, self.integ.velocity(self.vel)), status=f"t = {t:.5g} s")
        self.state = (self.integ.u, self.vel)
        return self.state

    io_event = "FEM_io"

    def write_partial(self, status):
        self.write_results(None, status=status, final=False)

    def output_parts(self, res):
        """The structure's output (none without -ssi_output): the groups its observers write
        (``Recorder.groups``: the receivers, with the ground's and the absolute acceleration under a
        support motion added here; the demands), the gravity case's and the support motion's,
        attributes and the run record."""
        cfg, comm, model, am, n_steps = self.cfg, self.comm, self.model, self.am, self.n_steps
        if self.out is None:
            return []
        groups = self.rec.groups(self.out)
        receivers = groups.pop("receivers", None)
        dt = self.grid.dt
        attrs = {"problem": "fem", "dt": dt, **damping_attrs(am, self.integ.a1, self.integ.modal),
                 "structure_mass": structure_mass(model, comm), "symmetry": symmetry_attr(cfg)}
        if self.gravity is not None:
            attrs["gravity"] = self.gravity.g
            if comm.getRank() == 0:
                dem = dict(self.demands.arrays(), reference_point=self.demand_spec.ref) if self.demands else None
                groups["gravity"] = self.gravity.group(dem)
        if self.support is not None:
            groups["seismic"] = self.support.arrays()
            attrs["seismic"] = "support motion (relative-motion form: u, velocity, acceleration relative to the base)"
            if receivers is not None and "acceleration" in receivers:
                receivers["ground_acceleration"] = self.ground_acceleration(receivers["t"])
                receivers["absolute_acceleration"] = (receivers["acceleration"]
                                                      + receivers["ground_acceleration"][:, None, :])
        extra = {"time_grid": {"dt_s": dt, "t_end_s": n_steps * dt, "n_steps": n_steps},
                 "fem": {"alpha_m": am, "rayleigh_a1": self.integ.a1, "n_steps": n_steps, "n_nodes": model.mesh.n_nodes,
                         "n_cells": model.mesh.n_cells, "n_dofs": model.dofmap.size, "mesh": model.mesh.source,
                         "elements": model.mesh.element_counts(),
                         "receiver_snap_distance": [float(d) for d in model.receiver_dist]}}
        if cfg.fem_integrator == "green":
            extra["fem"]["b"] = green_constants(dt, am, cfg.fem_newmark_alpha, cfg.fem_newmark_delta, self.integ.a1)
        return [(self.out, {"receivers": receivers, "attrs": attrs, "groups": groups or None,
                            "record": provenance(cfg, comm, extra)})]

    def written(self, res):
        cfg = self.cfg
        if self.out is None:
            return
        if cfg.plot and self.comm.getRank() == 0 and len(self.model.receiver_nodes):
            _plot(cfg.output, *self.rec.structure.rec.arrays())
        printf(f"[fem] wrote {cfg.output} (+ .xmf, .json)")

    def finish(self):
        self._advance("stepping" if self.n else "started", "finished")
        comm, model = self.comm, self.model
        t, u = self.rec.structure.rec.arrays()
        self.write_results(None, status=self.final_status())
        if comm.getRank() == 0 and len(model.receiver_nodes):
            printf(f"[fem] receiver 0 at t = {t[-1]:.5g} s: u = ({u[-1, 0, 0]:.6e}, {u[-1, 0, 1]:.6e}, "
                   f"{u[-1, 0, 2]:.6e}) m")
        self.integ.destroy()
        if self.gravity is not None:
            self.gravity.destroy()
        out = {"t": t, "u": u, "n_steps": self.n_steps, "alpha_m": self.am, "model": model}
        if self.demands is not None:
            out["demands"] = self.demands.arrays() if comm.getRank() == 0 else None
            self.demands.destroy()
        self.release_locks()                    # the run is done: its files are free again
        return out


def symmetry_attr(cfg):
    """The run's -ssi_symmetry planes as written ('' for none): a half (quarter) model's base shear,
    overturning moment and weight are the modelled part's (post --demands and --glance say so)."""
    text = str(cfg.get("symmetry", "") or "").strip()
    return "" if text.lower() == "none" else text


def structure_mass(model, comm):
    """Collective: the structure's mass [kg] (the lumped masses of the x translations of every node, the
    base's included; of the modelled part of a half model): W = m g is the weight of post --demands' V/W."""
    dm = model.dofmap
    d = dm.translation_dofs(np.arange(model.mesh.n_nodes))[:, 0]
    r0, r1 = model.m.getOwnershipRange()
    d = d[(d >= r0) & (d < r1)] - r0
    return float(comm.tompi4py().allreduce(float(model.m.getArray(readonly=True)[d].sum())))


def damping_attrs(am, a1, modal=None):
    """Output attributes of the structure's damping C = alpha_m M + rayleigh_a1 K (+ the modal damping's
    frequencies and ratios, ``fem.modal_damping``)."""
    out = {"alpha_m": float(am), "rayleigh_a1": float(a1),
           "damping": "C = alpha_m M + rayleigh_a1 K (Rayleigh; alpha_m in 1/s, rayleigh_a1 in s); damping ratio "
                      "of a mode of frequency f: alpha_m/(2 omega) + rayleigh_a1 omega/2, omega = 2 pi f"}
    if modal is not None:
        out.update(modal.attrs())
        out["damping"] += ("; + modal damping: ratio modal_damping_ratios[i] added in the mode of "
                           "modal_damping_frequencies_hz[i] (Hz), none in higher modes")
    return out


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


def structure_bytes(model, grid):
    """{what: bytes} of the structure's output: displacement, velocity (and rotation where the
    model has rotations) every snapshot; u, velocity, acceleration, rotation of every receiver
    every step."""
    from ..problem import TransientProblem
    rot = bool(np.any(model.dofmap.has_rotation))
    return {"structure fields": TransientProblem.field_bytes(model.mesh.n_nodes, 3 if rot else 2, grid),
            "structure receivers": 8.0 * 3 * 4 * len(model.receivers) * grid.n_steps}
