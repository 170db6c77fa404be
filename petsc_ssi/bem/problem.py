"""``BEMTransient``: the half-space alone (-ssi_problem bem) as an importable problem.

The stages of ``petsc_ssi.problem.TransientProblem``: the constructor reads the mesh, checks
every input and estimates the memory (``halfspace.HalfSpace.prepare``); ``setup`` assembles the lag
matrices and factorises the step matrix (``build.build_marcher``); ``step`` advances the Marcher one
step, records (``io.recorder``) and applies the divergence guard; ``finish`` writes receivers,
sidecars and the run record. ``state`` between steps: (u, p), the soil's displacement and
traction Vecs of the last step (owned layout).
"""
import time

import numpy as np

from ..petsc import printf
from ..monitor import staged, fmt_time
from ..io.output import Output, provenance
from ..problem import TransientProblem, no_output_refused
from .halfspace import HalfSpace
from .build import build_marcher
from .stability import DivergenceGuard
from . import options as _options  # noqa: F401  (declares the -ssi_ options of the half-space)


class BEMTransient(TransientProblem):
    kind = "bem"

    def __init__(self, cfg, comm=None, sources=None):
        """``sources``: what loads the soil (``petsc_ssi.sources``: surface tractions, a rigid motion of a
        region or a massless footing); None: those of the options (``sources.from_options``)."""
        super().__init__(cfg, comm)
        no_output_refused(cfg, "a BEM")
        self.check_output()
        self.log = printf if cfg.monitor else (lambda m: None)
        with staged("SSI BEM setup"):
            self.prob = HalfSpace(cfg, self.comm, log=printf, sources=sources)
            self.plan, self.ls = self.prob.prepare()
        self.grid = self.prob.grid
        self.march = self.rec = self.out = None
        self.footing = None                  # a massless footing's correction (sources/rigid.py)
        self.state = None
        self.check_disk()

    def output_bytes(self):
        g, p = self.grid, self.prob
        return {"soil fields": self.field_bytes(p.mesh.n_nodes, 2, g),       # displacement, traction
                "soil receivers": 8.0 * 3 * len(p.receivers) * g.n_steps}

    def setup(self):
        self._advance("created", "set up")
        p = self.prob
        with staged("SSI BEM assembly"):
            self.march, self.info = build_marcher(self.cfg, self.comm, p, self.plan, self.ls, p.known_u(),
                                              p.known_p(), self.log)
            if p.motion is not None:        # the motion source's step correction (a massless footing's)
                self.footing = p.motion.correction(self.comm, p, self.march)

    def start(self):
        self._advance("set up", "started")
        from ..io.recorder import Recorder
        from .recorder import SoilRecorder, at_rest
        rd = self._open_restart()
        self.out = Output(self.cfg.output, self.comm, resume=rd.output_state("out") if rd else None, run_id=self.run_id)
        self.rec = Recorder(self.cfg, self.comm, "BEM time loop", self.grid,
                            soil=SoilRecorder(self.out, self.comm, self.prob, self.march))
        if self.footing is not None:
            self.rec.add(self.footing, out=self.out)        # its motion series in checkpoints, its group
        if self.cfg.guard:
            self.rec.add(DivergenceGuard(self.cfg, self.prob, self.march, self.rec.norms))
        self._ut = self.march.u_tmpl.duplicate()            # the total field (a seismic input's u_sc + u_ff)
        if rd is None:                            # the fields of t = 0 (frame 0 of the XDMF)
            self.rec.initial(self.time(0), write=self.grid.writes(0),
                             soil=at_rest(self.prob, self.march, self.time(0), self._ut))
        self._resume()

    def checkpoint_state(self):
        serial = self.rec.state()
        serial.update(self._output_state("out", self.out))
        return self.march.checkpoint_vecs(), serial

    def restore_state(self, reader):
        n = int(self.restart["step"])
        self.march.restore(reader, n)
        self.rec.restore(reader.serial, n)
        self.march.norm_prefix_max[:] = np.maximum.accumulate(self.rec.unorm)    # the guard's running max

    def step(self, n):
        self._check_step(n)
        with staged("SSI BEM time loop"):
            u, p = self.march.step(self.footing.correct if self.footing is not None else None)
            nrm = u.norm()
            rec = self.rec
            w = min(100, n - 1)       # growth of |u| over the last (up to) 100 steps, shown by -ssi_monitor
            prev = rec.unorm[-w] if w else 0.0
            grow = f" growth x{nrm / prev:.3g}/{w} steps" if w and prev > 0 else ""
            t = self.time(n)
            self.n = n                        # the step is taken; its records follow
            ut = self.prob.total_field(u, t, self._ut)
            rec.step(n, t, soil=(ut, p), norm=nrm, status=f"t={t:.4g}s |u|={nrm:.3e}{grow}")   # and the guard
        self.state = (ut, p)
        return self.state

    def write_partial(self, status):
        self.write_results({"stats": {"steps_done": self.n}}, status=status, final=False)

    def output_parts(self, res):
        """The soil's output: the groups its observers write (``Recorder.groups``: the receivers, a
        prescribed region's resultants, a massless footing's input motion) and the seismic input's,
        attributes and the run record."""
        cfg, comm, prob = self.cfg, self.comm, self.prob
        groups = self.rec.groups(self.out)
        recd = groups.pop("receivers", None)
        attrs = {"problem": "bem", "cp": cfg.cp, "cs": cfg.cs, "rho": cfg.rho, "dt": prob.dt,
                 "scheme": cfg.scheme, "load_p0": cfg.load_p0, "load_history": cfg.load_history}
        if getattr(prob, "seismic", None) is not None:
            groups["seismic"] = prob.seismic.arrays()
            attrs["seismic"] = prob.seismic.kind
        if self.footing is not None:
            attrs["disp_rigid"] = "massless"
        if cfg.mesh_patch and cfg.load_group == "load":
            attrs["load_patch"] = cfg.mesh_patch     # half-widths a,b of the loaded rectangle
        record = provenance(cfg, comm, {"stats": res.get("stats", {})}, grid=prob.grid)
        return [(self.out, {"receivers": recd, "attrs": attrs, "record": record, "groups": groups or None})]

    def written(self, res):
        cfg = self.cfg
        if cfg.plot and self.comm.getRank() == 0 and res["u"] is not None:
            from ..plot import receiver_plot
            receiver_plot(cfg.output, cfg)

    def finish(self):
        self._advance("stepping" if self.n else "started", "finished")
        cfg, prob, plan, ls, info = self.cfg, self.prob, self.plan, self.ls, self.info
        rec = self.rec
        res = {"t": np.array(rec.times), "u": rec.soil_receivers(), "unorm": np.array(rec.unorm),
               "resultants": rec.soil.resultants(rec.steps, rec.times)}
        if self.footing is not None:
            res["input_motion"] = self.footing.arrays(rec.times)
        res["stats"] = {
            "assembly_s": info["t_asm"], "wall_s": time.perf_counter() - self.t_start, "lags": prob.L,
            "exact_lags": plan.Lx, "interp_k": plan.k if plan.active else 0, "interp": plan.method,
            "T_L": plan.TL if plan.active else None, "lag_bytes_exact": info["mem_exact"],
            "lag_bytes_interp": info["mem_interp"], "dense_lags": info["ndense"], "baij_lags": info["nbaij"],
            "single_lags": info.get("nsingle", 0),
            "mean_fill": info["fill"], "lag_bytes": info["mem"], "mem_estimate": prob.mem_estimate,
            "T_N": prob.T_N, "r_max": prob.r_max, "kernel_evaluations": ls.kernel_evaluations,
            "cache_hits": ls.cache_hits, "beta_min": prob.beta[0], "beta_max": prob.beta[1],
            "mem_peak_estimate": prob.mem_peak_estimate}
        from ..sysmem import peak_rss
        res["stats"]["peak_rss_max_rank_bytes"], res["stats"]["peak_rss_sum_bytes"] = peak_rss(self.comm)
        self.write_results(res, status=self.final_status())
        printf(f"[ssi] done in {fmt_time(res['stats']['wall_s'])}: output {cfg.output}")
        self.release_locks()                    # the run is done: its files are free again
        return res
