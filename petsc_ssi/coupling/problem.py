"""``SSITransient``: structure and half-space coupled (-ssi_problem ssi) as an importable problem.

The stages of ``petsc_ssi.problem.TransientProblem``: the constructor reads both meshes and the
interface and checks every input, then the memory (``model.build_coupled``, ``HalfSpace.prepare`` with the
interface matrices counted); ``setup`` assembles K and M and factorises D, assembles the BEM lag
matrices and factorises the step matrix, then builds the interface matrices (``step.Coupler``,
with the staggered or implicit strategy); ``step`` is one coupled step with the contact
iteration (``Coupler.step``); ``finish`` writes both outputs, the interface series and the run
record. ``state`` between steps: (u_soil, p_soil, u_structure, res) with ``res`` the step's
interface record (u_f, u_b, p, gap, p_N, status, iterations, resultants).
"""
import os
import time

import numpy as np

from ..petsc import printf, warn, SSIError
from ..monitor import staged, fmt_time
from ..io.output import Output
from ..problem import TransientProblem, no_output_refused
from ..io.output import provenance
from ..fem.forces import add_force_recorder
from ..io.recorder import InterfaceSeries
from ..bem.build import build_marcher
from ..fem.integrators import make_model_integrator
from ..fem.loads import load_history
from ..sources.nodal import NodalLoad
from ..fem.problem import damping_attrs, structure_mass, symmetry_attr
from . import options as _options  # noqa: F401  (declares the coupling's options, and the soil's and structure's)
from .model import build_coupled, interface_bytes
from .step import Coupler

INTERFACE_KEYS = ("uf", "ub", "p", "gap", "pN", "closed", "iterations", "changes", "force_fe", "force_be",
                  "moment_fe", "moment_be", "bem_residual", "force_map_error", "n_open")
# the keys with a value per interface dof or node: kept every -ssi_interface_stride steps
NODAL_KEYS = ("uf", "ub", "p", "gap", "pN", "closed", "uf_check", "uff", "pff")


class SSITransient(TransientProblem):
    kind = "ssi"

    def __init__(self, cfg, comm=None):
        super().__init__(cfg, comm)
        no_output_refused(cfg, "a coupled")
        self.check_output(also=(structure_output_path(cfg.output),))
        self.log = printf if cfg.monitor else (lambda m: None)
        comm = self.comm
        with staged("SSI setup"):
            self.hist = load_history(cfg, comm)
            self.prob, self.model, self.iface, self.integrator = build_coupled(cfg, comm)
            iface = self.iface
            from ..fem.demands import DemandSpec
            from ..petsc import collective
            with collective(comm, "checking the storey demands' options"):
                self.demand_spec = DemandSpec(cfg, self.model, "-ssi_structure_receivers", base="interface",
                                              ref_auto=interface_centroid(self.prob, iface))
            self.plan, self.ls = self.prob.prepare([
                f"[ssi] interface: {iface.n} nodes ({len(iface.be_elems)} soil elements, area {iface.area():.4g} m^2, "
                f"node spacing {iface.spacing:.3g} m), contact {cfg.contact}"
                + (f", cohesion p_C = {cfg.contact_cohesion:g} N/m^2" if cfg.contact == "unilateral" else "")
                + (f", preload {cfg.contact_preload}" if cfg.contact == "unilateral" and
                   str(cfg.contact_preload).strip().lower() != "none" else "")
                + f", {cfg.coupling} coupling"], interface_bytes(cfg, self.prob, self.model, iface, comm.getSize()),
                "interface matrices")
        self.grid = self.prob.grid
        self.coupler = self.rec = self.forces = self.demands = None
        self.state = None
        self.check_disk()

    defer_loop_line = True          # (printed in setup, once the structure's solves are timed)
    cpl_per_step = None

    def loop_estimate(self):
        """The soil's BEM loop and the coupling's per-step work (``coupling.cost.step_seconds``, the
        structure's solves timed after its factorisation): the sum ``petsc-ssi estimate`` prints as
        time_loop_s."""
        est = super().loop_estimate()
        if est is None or self.cpl_per_step is None:
            return est
        cpl = self.cpl_per_step * self.n_steps
        # (the toeplitz store's BEM prediction holds the step matrix's solves, toeplitz.step_lu_of; the dense model's too)
        sol = getattr(self.prob, "step_solve_s", 0.0) * self.n_steps
        return (est[0] + cpl, est[1] + self.cpl_per_step,
                f"the soil's BEM {est[0]:.3g} s"
                + (f" (its step matrix's solves {sol:.3g} s, toeplitz.step_lu)" if sol else "")
                + f" and the coupling {cpl:.3g} s, a solve with the structure's D {1e3 * self.fem_solve_s:.3g} ms as timed")

    def loop_model(self):
        model = super().loop_model()
        if model is None or self.cpl_per_step is None:
            return model
        c = self.cpl_per_step
        return lambda k: model(k) + c * k

    def output_bytes(self):
        from ..fem.problem import structure_bytes
        g, p = self.grid, self.prob
        out = {"soil fields": self.field_bytes(p.mesh.n_nodes, 2, g),
               "soil receivers": 8.0 * 3 * len(p.receivers) * g.n_steps}
        out.update(structure_bytes(self.model, g))
        # the interface's nodal series (u_f, u_b, p and u_f_check/u_ff: 3 per node; gap, p_N, closed: 1)
        # every -ssi_interface_stride steps
        kept = g.n_steps // max(1, int(self.cfg.interface_stride))
        out["interface series"] = 8.0 * (5 * 3 + 3) * self.iface.n * kept
        return out

    def setup(self):
        self._advance("created", "set up")
        cfg, comm, prob = self.cfg, self.comm, self.prob
        with staged("SSI FEM assembly"):
            self.model.assemble()
            _, self.integ, self.am = make_model_integrator(cfg, comm, self.grid.dt, self.model, integrator=self.integrator)
            from .cost import solve_seconds, step_seconds
            from ..bem.cost import load_constants
            self.fem_solve_s = solve_seconds(self.integ, comm)
            consts = load_constants(cfg.get("estimate_constants", ""))[0]
            from .columns import estimated_region_nodes, estimated_solved_columns, estimated_fem_solved_columns
            imp = cfg.coupling == "implicit"
            self.cpl_per_step = step_seconds(consts, self.iface.n,
                                             estimated_region_nodes(cfg, prob, self.iface.be_nodes), comm.getSize(),
                                             self.fem_solve_s, self.model.dofmap.size if imp else 0,
                                             estimated_solved_columns(cfg, prob, self.iface.be_nodes),
                                             estimated_fem_solved_columns(cfg, prob, self.iface.be_nodes, self.model,
                                                                          comm) if imp else None)
        self.print_loop_line()
        with staged("SSI BEM assembly"):
            self.march, self.info = build_marcher(cfg, comm, prob, self.plan, self.ls, None, prob.known_p(), self.log)
            self.coupler = Coupler(cfg, comm, prob, self.march, self.iface, self.integ, self.model)
            cp, n = self.coupler, 3 * self.iface.n
            nb = n if cp.Zmir is None else len(cp.Zmir.rep_cols)
            nf = n if getattr(cp, "DEmir", None) is None else len(cp.DEmir.rep_cols)
            fem = cfg.coupling == "implicit"
            printf(f"[ssi] interface matrices ({cfg.coupling} coupling, structure integrated by "
                   f"{self.integrator}): {nb} BEM" + (f" and {nf} FEM" if fem else "") + " solves"
                   + (f" (of {n} columns, the others mirror images)" if min(nb, nf if fem else nb) < n else "")
                   + f" in {fmt_time(cp.t_capacitance)} "
                   f"(BEM step matrix factorised once in {fmt_time(self.march.t_factor)})")
        self.fn = self.model.load_vec()
        self.load_source = NodalLoad(self.model.load_vec(), self.hist)      # F a(t) (sources/nodal.py)
        self.vel = self.integ.u.duplicate()

    @property
    def F(self):
        """The structure's spatial load Vec (the load source's F, after ``setup``): a script may
        change it between steps."""
        return self.load_source.F

    def load(self, k):
        """The structure's load of step k: at t_k as the cell mean (Green, staggered), or the mean
        over (t_{k-1}, t_k] (midpoint form, implicit)."""
        rule = "cell" if self.cfg.coupling == "staggered" or k == 0 else "step"
        return self.load_source.sample(self.fn, k, self.grid.dt, rule)

    def start(self):
        self._advance("set up", "started")
        from ..io.recorder import Recorder, StepClock
        from ..bem.recorder import SoilRecorder
        from ..fem.recorder import StructureRecorder
        cfg, comm = self.cfg, self.comm
        keys = INTERFACE_KEYS + (("uf_check",) if cfg.coupling == "implicit" else ()) + \
            (("uff",) if self.prob.seismic is not None else ()) + \
            (("pff",) if self.prob.has_interface_free_field else ())
        rd = self._open_restart()
        self.out = Output(cfg.output, comm, resume=rd.output_state("out") if rd else None, run_id=self.run_id)
        self.sout = Output(structure_output_path(cfg.output), comm, resume=rd.output_state("sout") if rd else None,
                           run_id=self.run_id)
        self.rec = Recorder(cfg, comm, "SSI time loop", self.grid,
                            soil=SoilRecorder(self.out, comm, self.prob, self.march),
                            structure=StructureRecorder(self.sout, self.model, comm),
                            interface=InterfaceRecord(keys, NODAL_KEYS, cfg.interface_stride, self.iface, self.grid))
        self.forces = add_force_recorder(cfg, self.sout, self.model, comm, self.rec)
        self.rec.add(_FiniteCheck(self.integ))
        self.clock = self.rec.add(StepClock(group=cfg.step_times), out=self.out)    # (-ssi_step_times: written)
        from ..fem.demands import Demands       # base shear, overturning moment, drifts (fem/demands.py)
        self.demands = self.rec.add(Demands(self.demand_spec, self.model, comm, "[ssi]"), out=self.sout)
        self._ut = self.march.u_tmpl.duplicate()
        self.integ.start(f0=self.load(0))
        if rd is None:                            # the records of t = 0 (and frame 0 of the XDMF files)
            from ..bem.recorder import at_rest
            self.rec.initial(self.time(0), write=self.grid.writes(0),
                             soil=at_rest(self.prob, self.march, self.time(0), self._ut),
                             structure=(self.integ.u, self.integ.velocity(self.vel)))
        self._resume()
        self.clock.start()

    def checkpoint_state(self):
        cp, law = self.coupler, self.coupler.law
        serial = self.rec.state()
        serial.update(self._output_state("out", self.out))
        serial.update(self._output_state("sout", self.sout))
        serial.update(self.integ.checkpoint_scalars())
        serial.update({"law_closed": law.closed, "law_ub_prev": law.ub_prev, "law_total_changes": law.total_changes,
                       "law_cycled_steps": np.asarray(law.cycled_steps, np.int64), "cp_pI_prev": cp.pI_prev,
                       "cp_closed_prev": cp.closed_prev})
        vecs = self.march.checkpoint_vecs()
        vecs.update(self.integ.checkpoint_vecs())
        vecs.update(self.rec.checkpoint_vecs())           # the observers' (member force envelopes)
        return vecs, serial

    def restore_state(self, reader):
        s, cp, law = reader.serial, self.coupler, self.coupler.law
        n = int(self.restart["step"])
        self.march.restore(reader, n)
        self.integ.restore(reader)
        self.rec.restore_vecs(reader)
        self.rec.restore(s, n)
        law.closed = np.asarray(s["law_closed"], bool).copy()
        law.ub_prev = np.asarray(s["law_ub_prev"], float).copy()
        law.total_changes = int(s["law_total_changes"])
        law.cycled_steps = [int(k) for k in s["law_cycled_steps"]]
        cp.pI_prev = np.asarray(s["cp_pI_prev"], float).copy()
        cp.closed_prev = np.asarray(s["cp_closed_prev"], bool).copy()

    def step(self, n):
        self._check_step(n)
        coupler, integ = self.coupler, self.integ
        with staged("SSI time loop"):
            uffI = self.prob.free_field_at(self.iface.be_nodes, self.time(n)) if self.prob.seismic is not None else None
            u, p, res = coupler.step(self.load(n), uffI, self.prob.interface_free_field(n))
            t = self.time(n)
            if res["cycled"]:
                coupler.law.cycled_steps.append(n)
                warn(f"step {n} (t = {t:.4g} s): the contact status did not settle in {res['iterations']} "
                     f"iterations (cycling); the step is accepted with the last status (-ssi_contact_max_iter)")
            nrm = u.norm()
            n_open = int((~res["closed"]).sum())
            res["n_open"] = n_open
            self.n = n                        # the step is taken; its records follow
            ut = self.prob.total_field(u, t, self._ut)              # u_sc + u_ff with a seismic input
            self.rec.step(n, t, soil=(ut, p), structure=(integ.u, integ.velocity(self.vel)), interface=res,
                          norm=nrm, status=f"t={t:.4g}s |u_soil|={nrm:.3e} open {n_open}/{coupler.nI} "
                                           f"it {res['iterations']}")
        self.state = (ut, p, integ.u, res)
        return self.state

    def results(self):
        """Collective: the series so far (soil receivers, structure, interface; rank 0)."""
        rec, comm = self.rec, self.comm
        times = rec.times
        inter = rec.interface.laid_out(times)
        st, su = rec.structure.rec.arrays()
        sall = rec.structure.rec.all_arrays() if comm.getRank() == 0 else None
        inter["preload"] = self.coupler.preload            # p_w [N/m^2] (0: none)
        dem = self.demands.group() if comm.getRank() == 0 else None
        return {"t": np.asarray(times), "u": rec.soil_receivers(), "structure_t": st, "structure_u": su,
                "structure": sall, "interface": inter, "unorm": np.asarray(rec.unorm), "demands": dem}

    def write_partial(self, status):
        self.write_results({"stats": {"steps_done": self.n}}, status=status, final=False)

    def output_parts(self, res):
        """Both outputs: the soil's (receivers, the interface series, the seismic input, the step
        times) and the structure's (receivers, demands), each with attributes; the run record in
        the soil's."""
        cfg, comm, prob, model = self.cfg, self.comm, self.prob, self.model
        attrs = {"problem": "ssi", "cp": cfg.cp, "cs": cfg.cs, "rho": cfg.rho, "dt": self.grid.dt, "scheme": cfg.scheme,
                 "contact": cfg.contact, "contact_cohesion": cfg.contact_cohesion,
                 "contact_preload": (float(self.coupler.preload) if np.ndim(self.coupler.preload) == 0
                                     else np.asarray(self.coupler.preload)),
                 "structure_output": os.path.basename(structure_output_path(cfg.output))}
        if getattr(prob, "seismic", None) is not None:
            attrs["seismic"] = prob.seismic.kind
        record = provenance(cfg, comm, {"stats": res["stats"]}, grid=prob.grid)
        # the groups the observers write: the soil's receivers, the interface series, the step times
        # (-ssi_step_times); the structure's receivers and demands
        groups, sgroups = self.rec.groups(self.out), self.rec.groups(self.sout)
        recd, srecd = groups.pop("receivers", None), sgroups.pop("receivers", None)
        if getattr(prob, "seismic", None) is not None:
            groups["seismic"] = prob.seismic.arrays()
        sattrs = {"problem": "ssi-structure", "dt": self.grid.dt, **damping_attrs(self.am, self.integ.a1, self.integ.modal),
                  "structure_mass": structure_mass(model, comm), "symmetry": symmetry_attr(cfg)}
        return [(self.out, {"receivers": recd, "attrs": attrs, "record": record, "groups": groups or None}),
                (self.sout, {"receivers": srecd, "attrs": sattrs, "record": None, "groups": sgroups or None})]

    def finish(self):
        self._advance("stepping" if self.n else "started", "finished")
        cfg, comm, coupler, march, plan, prob = self.cfg, self.comm, self.coupler, self.march, self.plan, self.prob
        res = self.results()
        law = coupler.law
        nch = law.total_changes
        stats = {"wall_s": time.perf_counter() - self.t_start, "assembly_s": self.info["t_asm"],
                 "lag_bytes": self.info["mem"], "bem_factor_s": march.t_factor,
                 "capacitance_setup_s": coupler.t_capacitance, "status_changes": int(nch),
                 "capacitance_factorisations": coupler.solver_cap().n_factor,
                 "capacitance_factor_s": coupler.solver_cap().t_factor, "contact_algebra_s": law.t_algebra,
                 "cycled_steps": law.cycled_steps, "interface_nodes": self.iface.n, "lags": prob.L,
                 "exact_lags": plan.Lx, "interp_k": plan.k if plan.active else 0,
                 "beta_min": prob.beta[0], "beta_max": prob.beta[1], "alpha_m": self.am,
                 "rayleigh_a1": self.integ.a1}
        from ..sysmem import peak_rss
        stats["peak_rss_max_rank_bytes"], stats["peak_rss_sum_bytes"] = peak_rss(comm)
        res["stats"] = stats
        if cfg.contact == "unilateral":
            per = law.t_algebra / max(nch, 1)
            printf(f"[ssi] contact: {nch} status changes in {int((res['interface']['changes'] > 0).sum())} steps, "
                   f"{coupler.solver_cap().n_factor} interface factorisations "
                   f"({fmt_time(coupler.solver_cap().t_factor)}), active-set algebra {fmt_time(law.t_algebra)} in "
                   f"all ({per * 1e3:.3g} ms per status change) vs {fmt_time(march.t_factor)} for one "
                   "factorisation of the BEM step matrix")
        self.write_results(res, status=self.final_status())
        self.coupler.destroy()
        self.integ.destroy()
        self.demands.destroy()
        printf(f"[ssi] done in {fmt_time(stats['wall_s'])}: output {cfg.output}")
        self.release_locks()                    # the run is done: its files are free again
        return res


def structure_output_path(path):
    stem, ext = os.path.splitext(path)
    return stem + "_structure" + (ext or ".h5")


def interface_centroid(prob, iface):
    """The interface's area centroid at z = 0 (the soil surface), moved onto the -ssi_symmetry
    planes (the whole interface's centroid lies on them) [m]: the overturning moment's reference."""
    from ..bem.resultants import area_moments
    a, b = area_moments(prob.mesh, iface.be_elems, iface.be_nodes)
    c = b.sum(axis=0) / a.sum()
    c[2] = 0.0
    for axis, _ in prob.planes:
        c[axis] = 0.0
    return c


class InterfaceRecord(InterfaceSeries):
    """The coupling's interface series (``io.recorder.InterfaceSeries``) laid out for its output group
    'interface' (``laid_out``): the vectors per node (n_I, 3) at each kept step, t, and with
    -ssi_interface_stride > 1 the nodal series' own steps and times; the nodes' x and normal. The static
    contact pressure p_w is the file's attribute contact_preload [N/m^2], not a series."""

    VECTORS = ("uf", "ub", "p", "uf_check", "uff", "pff")

    def __init__(self, keys, nodal, stride, iface, grid):
        super().__init__(keys, nodal, stride)
        self.iface, self.grid = iface, grid

    def laid_out(self, times):
        """{name: array} (every rank holds the same)."""
        nI = self.iface.n
        inter = self.arrays()
        nodal = inter.pop("nodal_steps")
        for k in (k for k in self.VECTORS if k in inter):
            inter[k] = inter[k].reshape(len(nodal), nI, 3)
        inter["n_open"] = np.asarray(inter["n_open"], np.int64)
        inter["t"] = np.asarray(times)
        if self.stride > 1:                       # the nodal series' own steps and times
            inter["nodal_steps"] = nodal
            inter["t_nodal"] = self.grid.time(nodal) if len(nodal) else np.zeros(0)
        inter["x"] = self.iface.x
        inter["normal"] = self.iface.n_b
        return inter

    def groups(self, steps, times):
        # time series only (readers slice every dataset of the group)
        return {"interface": self.laid_out(times)}


class _FiniteCheck:
    """An observer of the recorder: stop the coupled run once a step's soil or structure solution is
    not finite (after the step is recorded, before any checkpoint of it)."""

    def __init__(self, integ):
        self.integ = integ

    def observe(self, n, t, step):
        if not np.isfinite(step["norm"]) or not np.isfinite(self.integ.u.norm()):
            raise SSIError(f"the coupled solution is not finite at step {n} (t = {t:.4g} s): check dt "
                           "(beta = c dt / l) and -ssi_coupling_traction")
