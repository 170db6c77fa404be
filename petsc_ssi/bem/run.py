"""``-ssi_problem bem``: the half-space BEM run, from options to HDF5 (the stages: ``problem.py``).

Order of work: every input check (collective, one-line errors) and the memory
estimate come before any assembly.
"""
import math
import os
import time

import numpy as np

from ..petsc import init, SSIError, collective_error, printf, warn
from ..monitor import event, fmt_time
from ..mesh import surface
from ..io.output import provenance
from .. import timegrid
from . import symmetry, receivers as rec, histories, lagmats
from .resultants import RigidMotion
from .model import Material, Regions, LagSet, causal_lags, machine_memory
from . import interp
from .march import Marcher
from .stability import guard_reference, guard_trips


def _pair(text, name):
    try:
        v = [float(s) for s in text.split(",")]
    except ValueError:
        raise SSIError(f"-ssi_{name} '{text}': expected 'a,b'") from None
    if len(v) != 2 or min(v) <= 0:
        raise SSIError(f"-ssi_{name} '{text}': expected two positive numbers 'a,b'")
    return v


def load_mesh(cfg, planes, comm):
    """Collective: the surface mesh (grid generator or gmsh; rank 0 reads, broadcast)."""
    Lx, Ly = _pair(cfg.mesh_size, "mesh_size")
    patch = _pair(cfg.mesh_patch, "mesh_patch") if cfg.mesh_patch else None
    xmin = 0.0 if any(a == 0 for a, _ in planes) else None
    ymin = 0.0 if any(a == 1 for a, _ in planes) else None
    mpi = comm.tompi4py()
    err, mesh = None, None
    if comm.getRank() == 0:
        try:
            if cfg.mesh == "grid":
                mesh = surface.grid(Lx, Ly, cfg.mesh_h, patch, xmin, ymin)
            else:
                params = {"Lx": Lx, "Ly": Ly, "h": cfg.mesh_h,
                          "xmin": -Lx / 2 if xmin is None else 0.0,
                          "ymin": -Ly / 2 if ymin is None else 0.0}
                if patch:
                    params.update({"a": patch[0], "b": patch[1]})
                from ..fem.mesh import parse_mesh_params
                params.update(parse_mesh_params(cfg.get("mesh_params", ""), "-ssi_mesh_params"))
                mesh = surface.read_gmsh(cfg.mesh, params)
            mesh.check()
            z = np.abs(mesh.nodes[:, 2])
            ext = float(np.ptp(mesh.nodes[:, :2], axis=0).max()) or 1.0
            if z.max() > 1e-9 * ext:
                k = int(z.argmax())
                raise SSIError(f"-ssi_mesh {cfg.mesh}: the surface mesh must lie in the plane z = 0 (the free "
                               f"surface of the half-space z < 0); node {k} is at z = {mesh.nodes[k, 2]:.6g} m")
        except SSIError as exc:
            err = str(exc)
        except Exception as exc:  # unreadable file, gmsh failure
            err = f"-ssi_mesh {cfg.mesh}: cannot read the mesh ({type(exc).__name__}: {exc})"
    collective_error(mpi.bcast(err), comm)
    return mpi.bcast(mesh)


def _history(cfg, which):
    """The -ssi_<which>_history as a callable, read and checked now."""
    try:
        return histories.make(cfg.get(which + "_history"), cfg.get(which + "_t0"), cfg.get(which + "_table"))
    except SSIError as exc:
        raise SSIError(f"-ssi_{which}_history {cfg.get(which + '_history')}: {exc}") from None


class BEMProblem:
    """Everything a BEM run needs, checked before heavy work (collective)."""

    def __init__(self, cfg, comm, log=printf):
        self.cfg, self.comm, self.log = cfg, comm, log
        self.mat = Material(cfg.cp, cfg.cs, cfg.rho)
        self.planes = symmetry.parse(cfg.symmetry)
        self.mesh = load_mesh(cfg, self.planes, comm)
        h = float(self.mesh.element_sizes().max())
        self.h = h
        symmetry.check_mesh(self.mesh.nodes, self.planes, h)
        bad, ang = surface.kinks(self.mesh, self.planes)
        if len(bad):
            printf(f"[ssi] {len(bad)} non-smooth surface nodes (edges/corners, up to {ang.max():.3g} degrees): "
                   f"free term from the interior solid angle (Hartmann)")
        self.dt = cfg.dt
        # enough steps to reach t_end (a t_end off the step grid is passed, not cut)
        self.n_steps = timegrid.n_steps(cfg.t_end, cfg.dt)
        load = self.mesh.select(cfg.load_group) if cfg.load_group else ()
        disp = self.mesh.select(cfg.disp_group) if cfg.disp_group else ()
        if cfg.load_group and cfg.load_p0 == 0.0:
            warn("-ssi_load_group is set but -ssi_load_p0 is 0: the run is load-free")
        if cfg.user_set("load_p0") and not cfg.load_group:
            warn("-ssi_load_p0 is set but no -ssi_load_group: nothing is loaded")
        if cfg.user_set("disp_value") and not cfg.disp_group:
            warn("-ssi_disp_value is set but no -ssi_disp_group: nothing is prescribed")
        # histories are built (and tables read and checked) before any heavy work
        self._load_f = _history(cfg, "load") if len(load) else None
        self._disp_f = _history(cfg, "disp") if len(disp) else None
        self.regions = Regions(self.mesh, load, disp)
        for name in ("disp_rotation", "disp_ref"):
            if cfg.user_set(name) and not cfg.disp_group:
                warn(f"-ssi_{name} is set but no -ssi_disp_group: nothing is prescribed")
        symmetry.check_compatible(self.planes, np.array([0.0, 0.0, -cfg.load_p0]) if len(load) else None, None)
        self.motion = RigidMotion(cfg, self.mesh, self.regions, self.planes) if len(disp) else None
        self.receivers = rec.parse(cfg.receivers)
        for p in self.receivers:
            q, _ = symmetry.map_point(p, self.planes)
            rec.locate(self.mesh, q)
            if abs(p[2]) > 1e-6 * max(h, 1.0):
                raise SSIError(f"receiver ({p[0]:g}, {p[1]:g}, {p[2]:g}) is not on the surface z = 0")
        self._lags()
        self._warnings(h)

    def _lags(self):
        VX = self.mesh.cell_coords()
        ext = np.abs(VX).max(axis=(0, 1))
        if self.planes:
            lo = -ext
        else:
            lo = VX.min(axis=(0, 1))
        hi = VX.max(axis=(0, 1))
        self.r_max = float(np.linalg.norm(hi - lo))
        self.T_N = self.r_max / self.mat.cs
        causal = causal_lags(self.r_max, self.mat, self.dt)
        self.L = max(2, min(causal, self.n_steps + 1))

    def _warnings(self, h):
        cfg = self.cfg
        sizes = self.mesh.element_sizes()
        lmin, lmax = sizes.min(), sizes.max()
        self.beta = (self.mat.cs * self.dt / lmax, self.mat.cp * self.dt / lmin)
        if cfg.warn_beta and (self.beta[0] < 0.3 or self.beta[1] > 1.3):
            warn(f"beta = c dt / l spans [{self.beta[0]:.3f}, {self.beta[1]:.3f}] (c_s with the largest, "
                 f"c_p with the smallest node spacing), outside [0.3, 1.3]: the time marching may be "
                 f"inaccurate or unstable")
        for p in self.receivers:
            self.diffraction_warning(p[None], f"receiver ({p[0]:g}, {p[1]:g}, {p[2]:g})")

    def diffraction_warning(self, points, what):
        """Warn (rank 0) when waves from the load diffracted at the truncation edge reach any of
        ``points`` (e.g. a receiver, or the structure's interface nodes) before t_end: the
        earliest arrival over the points, path load -> edge -> point at c_p."""
        if not self.regions.n_load or not len(points):
            return None
        src = self.mesh.nodes[self.regions.load_nodes]
        edge = self._edge_points()
        if not len(edge):
            return None
        d_se = np.linalg.norm(src[:, None, :2] - edge[None, :, :2], axis=2).min(0)
        t_d = np.inf
        for p in np.atleast_2d(points):
            q, _ = symmetry.map_point(p, self.planes)
            t_d = min(t_d, (d_se + np.linalg.norm(edge[:, :2] - q[:2], axis=1)).min() / self.mat.cp)
        if t_d < self.cfg.t_end:
            warn(f"{what}: waves diffracted at the mesh edge arrive at t = {t_d:.4g} s < t_end = "
                 f"{self.cfg.t_end:g} s")
        return t_d

    def _edge_points(self):
        """Nodes on the truncation edge (not on a symmetry plane)."""
        x = self.mesh.nodes
        out = np.zeros(len(x), bool)
        for ax in (0, 1):
            lo, hi = x[:, ax].min(), x[:, ax].max()
            tol = 1e-9 * max(abs(lo), abs(hi), 1.0)
            on_plane = any(a == ax for a, _ in self.planes)
            out |= np.abs(x[:, ax] - hi) < tol
            if not on_plane:
                out |= np.abs(x[:, ax] - lo) < tol
        return x[out]

    def summary(self):
        mesh = self.mesh
        nimg = len(symmetry.images(self.planes))
        return (f"[ssi] BEM: {mesh.n_cells} nine-node elements ({mesh.n_cells * nimg} with symmetry images), "
                f"{mesh.n_nodes} nodes, {3 * mesh.n_nodes} DOFs; {self.regions.n_t} traction nodes; "
                f"dt {self.dt:g} s, {self.n_steps} steps, scheme {self.cfg.scheme}; "
                f"r_max {self.r_max:.4g} m, T_N = r_max/c_s = {self.T_N:.4g} s; lags stored {self.L} "
                f"(causal limit {causal_lags(self.r_max, self.mat, self.dt)}); "
                f"beta in [{self.beta[0]:.3f}, {self.beta[1]:.3f}]")

    def interp_plan(self):
        """The lag interpolation plan from -ssi_interp* (auto: the paper's rule)."""
        c = self.cfg
        method, TL, k = c.interp, c.interp_tl, c.interp_k
        if method == "auto":
            src = (self.mesh.nodes[self.regions.load_nodes].mean(0) if self.regions.n_load
                   else np.zeros(3))
            for ax, _ in self.planes:      # the whole (mirrored) load is centred on the plane
                src[ax] = 0.0
            sites = getattr(self, "sites", np.zeros((0, 3)))
            pts = np.vstack([np.asarray(self.receivers).reshape(-1, 3), sites])
            TL, k, why = interp.auto(self.mat.cs, self.dt, self.L, pts, src)
            if len(sites):
                why += f" (points of interest: {len(self.receivers)} receivers and {len(sites)} interface nodes)"
            method = "chebyshev"
            printf(f"[ssi] -ssi_interp auto: {why}")
        plan = interp.Plan(method, self.dt, self.L, TL if TL else None, k, c.interp_grading)
        if c.interp != "none" and not plan.active:
            printf("[ssi] lag interpolation falls back to exact lags (T_L >= T_N or no lag to replace)")
        self.plan = plan
        return plan

    def prepare(self, extra=(), extra_bytes=0.0, extra_what=""):
        """Collective: print the summary (and ``extra`` lines), choose the interpolation
        plan, set up the LagSet and check the memory (with ``extra_bytes`` of the run's other
        dense data); returns (plan, lagset)."""
        printf(self.summary())
        for line in extra:
            printf(line)
        plan = self.interp_plan()
        printf("[ssi] " + plan.describe())
        ls = self.lagset(plan)
        if ls.balance is not None:
            n = [b - a for a, b in ls.ranges]
            printf(f"[ssi] soil nodes over {len(n)} ranks: {min(n)}..{max(n)} per rank, -ssi_partition "
                   f"{self.cfg.partition} (estimated work max/mean {ls.balance[0]:.3f}; equal node counts "
                   f"{ls.balance[1]:.3f})")
        self.check_memory(ls, plan, extra_bytes, extra_what)
        from . import lagstore
        err = None
        try:
            self.lags_manifest = lagstore.check(self.cfg, self.comm, self, plan)
        except SSIError as exc:
            err = str(exc)
        collective_error(err, self.comm)
        return plan, ls

    def quad_options(self):
        c = self.cfg
        return {"gauss": c.gauss, "singular_order": c.singular_order, "subdivisions": c.subdivisions,
                "near_factor": c.near_factor, "max_subdivisions": c.max_subdivisions, "cache": c.cache,
                "cache_share": c.cache_share}

    def lagset(self, plan=None):
        """The LagSet of this run; ``plan``: the interpolation plan (made here if not given), whose
        matrices and their uses weigh in the partition of the nodes over the ranks. The uses are
        those of a run of L steps (the lags it reaches), not of this run's steps: the partition, and
        with it every rounding of a parallel run, depends on the stored lags only, so a run stopped
        after n steps equals a run of n steps bit for bit (tests/test_output_survives.py)."""
        from .partition import lag_weights
        plan = plan if plan is not None else self.interp_plan()
        interp = [plan.kernel_time(j)[0] for j in range(plan.k)] if plan.active else []
        opts = dict(self.quad_options(), partition=self.cfg.partition, work_lags=plan.Lx,
                    lag_weights=lag_weights(plan.Lx, self.L, self.cfg.scheme.startswith("stabili"), interp))
        return LagSet(self.comm, self.mesh, self.mat, self.dt, self.L, self.regions, self.planes, opts)

    def check_memory(self, ls, plan=None, extra_bytes=0.0, extra_what=""):
        """Collective: refuse runs whose lag matrices would not fit; if the
        dense lags of the automatic storage choice would not fit but block-
        sparse storage would, store every lag block-sparse (and say so).
        ``extra_bytes``: memory of the whole run (all ranks) that lives beside the
        stored lags after assembly (the coupling's dense interface matrices)."""
        c = self.cfg
        limit = c.memory_limit * 1e9 if c.memory_limit > 0 else 0.8 * machine_memory()
        # the limit holds per node: the run's peak is shared by its ranks, of which
        # ``share`` run on the most loaded node (all of them on one machine)
        mpi = self.comm.tompi4py()
        from mpi4py import MPI
        node = mpi.Split_type(MPI.COMM_TYPE_SHARED)
        share = mpi.allreduce(node.Get_size(), op=MPI.MAX) / float(mpi.Get_size())
        n_nodes = mpi.allreduce(1 if node.Get_rank() == 0 else 0)
        node.Free()
        extra_bytes = float(extra_bytes)
        lags = plan.Lx if plan is not None and plan.active else self.L
        extra = [plan.kernel_time(j)[0] for j in range(plan.k)] if plan is not None and plan.active else []
        self.lag_fill = c.lag_fill
        sf = int(c.lag_single_from)
        load = not c.get("lags_load")           # (a run with loaded lags does not assemble)
        if sf > max([lags] + list(extra)):
            warn(f"-ssi_lag_single_from {sf}: beyond the {max([lags] + list(extra))} stored lags, every lag "
                 "stays in double precision")
        # fast first: the blocks of a sample of rows; a run far over the limit even with every lag
        # block-sparse is refused now, before the full O(N E) count
        est0, peak0, _ = ls.estimate_memory(lags, "sparse", c.lag_fill, extra, sample=64, single_from=sf)
        peak0 = max(peak0, est0 + extra_bytes)
        if share * peak0 > 1.5 * limit:
            raise SSIError(f"the lag matrices need about {share * peak0 / 1e9:.3g} GB at assembly (estimated from a "
                           f"sample of rows, every lag block-sparse) on {'the most loaded node' if n_nodes > 1 else 'this node'}, "
                           f"more than the {limit / 1e9:.3g} GB available (-ssi_memory_limit, per node); use symmetry "
                           "planes, -ssi_interp, a coarser mesh, a shorter -ssi_t_end or more nodes")
        est, peak, nd = ls.estimate_memory(lags, c.lag_storage, c.lag_fill, extra, single_from=sf, load=load)
        peak = max(peak, est + extra_bytes)
        if share * peak > limit and c.lag_storage == "auto":
            est2, peak2, _ = ls.estimate_memory(lags, "sparse", c.lag_fill, extra, single_from=sf, load=load)
            peak2 = max(peak2, est2 + extra_bytes)
            if share * peak2 <= limit:
                self.log(f"[ssi] memory: {nd} dense lags would need a {peak / 1e9:.3g} GB peak, over the "
                         f"{limit / 1e9:.3g} GB limit: all lags block-sparse ({peak2 / 1e9:.3g} GB)")
                self.lag_fill = 1.01
                est, peak, nd = est2, peak2, 0
        self.mem_estimate = est
        self.mem_peak_estimate = peak
        where = (f", {share * peak / 1e9:.3g} GB on the most loaded of {n_nodes} nodes" if n_nodes > 1 else "")
        more = f", {extra_what} {extra_bytes / 1e9:.3g} GB" if extra_bytes else ""
        self.log(f"[ssi] memory estimate: lag matrices {est / 1e9:.3g} GB ({nd} dense lags){more}, "
                 f"peak {peak / 1e9:.3g} GB{where} (limit {limit / 1e9:.3g} GB per node)")
        if share * peak > limit:
            raise SSIError(f"the lag matrices need about {share * peak / 1e9:.3g} GB at assembly on "
                           f"{'the most loaded node' if n_nodes > 1 else 'this node'}, more than the "
                           f"{limit / 1e9:.3g} GB available (-ssi_memory_limit, per node); use symmetry planes, "
                           f"-ssi_interp, a coarser mesh, a shorter -ssi_t_end or more nodes")

    def known_p(self):
        c = self.cfg
        f = self._load_f
        tr = np.array([0.0, 0.0, -c.load_p0])   # p0 > 0 pushes the surface down (-z)
        nl = self.regions.n_load

        def kp(n):
            return np.tile(tr * histories.step_mean(f, n, self.dt, c.load_history, c.load_t0), nl)
        return kp

    def disp_factor(self, n):
        """h(t_n) of the prescribed motion."""
        return float(self._disp_f(n * self.dt))

    def known_u(self):
        """callable(n) -> the prescribed displacements of step n at the region's nodes (3 n_disp,):
        the rigid motion h(t_n) [u0 + theta0 x (x - x_ref)] (``resultants.RigidMotion``)."""
        if not self.regions.n_disp:
            return lambda n: np.zeros(0)
        return lambda n: self.motion.values(self.disp_factor(n))


def run_bem(cfg, comm=None):
    """Collective: the whole BEM run (``problem.BEMTransient``). Returns a dict of results (rank 0
    has receivers)."""
    PETSc = init()
    comm = comm or PETSc.COMM_WORLD
    if cfg.get("check_stability"):
        from .stability import check_stability     # -ssi_check_stability: a coarse surrogate only
        return check_stability(cfg, comm, lambda c: run_bem(c, comm))
    from .problem import BEMTransient
    return BEMTransient(cfg, comm).run()


# One core's rates on the development machine (jobscripts/dgemm_rate.py): the dense panel product
# x @ A^T and the block-sparse panel kernel (bem/bsr.py) in GF/s at b = 8, 16, 32 states, and the
# matrix streaming rate of a per-step product in GB/s. Only the automatic block size uses them.
PANEL_B = (8, 16, 32)
PANEL_DENSE_GFPS = (19.7, 27.7, 38.1)
PANEL_SPARSE_GFPS = (8.2, 18.8, 32.2)
STREAM_GBPS = 22.0


def _sub_candidates(b, sub=0):
    """The sub-block sizes tried with blocks of b steps: ``sub`` if set, else b (one level) and
    b/2, b/4 down to 8 steps (narrower panels run below the streaming rate of a product)."""
    if sub:
        return (min(sub, b),)
    return tuple(sorted({b} | {b // q for q in (2, 4) if b // q >= 8}, reverse=True))


def choose_block(dense_bytes, sparse_bytes, stabilized=True, candidates=(1, 2, 4, 8, 12, 16, 24, 32),
                 sparse_blocks=None, sub=0):
    """(b, s): the steps per block and per sub-block that minimise the modelled time per step of the
    history sum, from the bytes of each stored matrix (index 0: lag 1, ..., then the interpolating
    ones, taken as the lags that follow; dense and block-sparse apart): in a block of a run long
    enough to reach every lag (``march.block_terms``), its panel products at the rates above for
    their widths (2 flops per stored value and state) and the per-step products, streamed. b = 1
    streams every matrix every step. ``sparse_blocks``: the 3x3 blocks of the block-sparse matrices
    (18 flops each per state; default their bytes / 76, the double blocks; single-precision ones
    store 40 B a block); ``sub``: a fixed sub-block size (0: chosen too). Step by step is an
    outcome only when 1 is a candidate: a user's -ssi_history_block b (candidates (b,)) is kept."""
    from .march import block_terms
    d = np.asarray(dense_bytes, float)
    s = np.asarray(sparse_bytes, float)
    sb = s / 76.0 if sparse_blocks is None else np.asarray(sparse_blocks, float)
    every = d + s
    nmat = len(every)
    best, best_t = ((1, 1), float(np.sum(every[1:])) / (STREAM_GBPS * 1e9)) if 1 in candidates else (None, np.inf)

    def rates(w):                                         # the panel rates at width w, flop/s
        return np.interp(w, PANEL_B, PANEL_DENSE_GFPS) * 1e9, np.interp(w, PANEL_B, PANEL_SPARSE_GFPS) * 1e9
    for b in candidates:
        if b < 2:
            continue
        n = b * (-(-(nmat + 3) // b)) + 1 + np.arange(b)      # one block past every lag's start
        for sub_b in _sub_candidates(b, sub):
            rate = {w: rates(w) for w in (b, sub_b)}
            t = 0.0
            for i in range(1, nmat):
                if every[i] == 0.0:
                    continue
                # a lag from b + 2 on reads only states known at the block's start
                steps, wb, ws = block_terms(n, [i + 1], b, sub_b, stabilized) if i + 1 < b + 2 else (0, b, 0)
                for w, cnt in ((b, wb / b), (sub_b, ws / sub_b)):
                    if cnt:
                        rd, rs = rate[w]
                        t += cnt * w * (d[i] * 2 / 8 / rd + sb[i] * 18 / rs)
                t += steps * every[i] / (STREAM_GBPS * 1e9)
            t /= b
            if t < best_t or best is None:
                best, best_t = (b, sub_b), t
    return best


def history_block(cfg, dense_bytes=None, sparse_bytes=None, sparse_blocks=None):
    """(b, s): the steps per block of the time-blocked history sum and per sub-block:
    -ssi_history_block and -ssi_history_sub, or with 0 the ``choose_block`` of the stored
    matrices' bytes (b = 1 without them)."""
    b = int(cfg.get("history_block") or 0)
    sub = int(cfg.get("history_sub") or 0)
    if b and (sub or b == 1 or dense_bytes is None):
        return b, min(sub, b) if sub else b
    if dense_bytes is None:
        return 1, 1
    return choose_block(dense_bytes, sparse_bytes, cfg.scheme.startswith("stabili"),
                        candidates=(b,) if b else (1, 2, 4, 8, 12, 16, 24, 32), sparse_blocks=sparse_blocks,
                        sub=sub)


def _block_of(cfg, comm, H, G, HI, GI):
    """history_block from this run's Mats (None: empty): per stored matrix the bytes of its H and
    of its G (read by the same panel products), dense or block-sparse, summed over the ranks."""
    from . import bsr
    Hs, Gs = list(H) + list(HI), list(G) + [None] * (len(H) - len(G)) + list(GI) + [None] * (len(HI) - len(GI))
    d = np.zeros((3, len(Hs)))              # dense bytes, block-sparse bytes, block-sparse blocks
    for i, (Hm, Gm) in enumerate(zip(Hs, Gs)):
        for M in (Hm, Gm):
            if M is None:
                continue
            ctx = bsr.context(M)
            d[1 if ctx is not None else 0, i] += lagmats.mat_bytes(M)
            if ctx is not None:
                d[2, i] += ctx.indices.size
    tot = np.zeros_like(d)
    comm.tompi4py().Allreduce(d, tot)
    return history_block(cfg, tot[0], tot[1], tot[2])


def _say_block(march):
    if march.block > 1:
        subs = (f" in sub-blocks of {march.sub} (-ssi_history_sub)" if march.sub < march.block else "")
        printf(f"[ssi] history sum: time-blocked, {march.block} steps per block{subs} (-ssi_history_block; 1: step "
               "by step)")
    else:
        printf("[ssi] history sum: step by step (-ssi_history_block 1)")


def build_bem(cfg, comm, prob, plan, ls, known_u, known_p, log=printf):
    """Collective: assemble the lag matrices (exact and interpolating), factorise
    the step matrix and hand the Mats to a Marcher. Returns (marcher, info)."""
    PETSc = init()
    from .. import numba_cache_warm
    if not numba_cache_warm() and not os.environ.get("PETSC_SSI_WARMUP"):
        from .model import announce_compile
        announce_compile()
    t0 = time.perf_counter()
    if cfg.get("lags_load"):
        return _load_bem(cfg, comm, prob, plan, ls, known_u, known_p, log, t0)
    single = int(cfg.lag_single_from)
    ls.assemble(monitor=cfg.monitor, lag_hi=plan.Lx, single_from=single)
    N = prob.mesh.n_nodes
    r0, r1 = ls.node_range
    march = Marcher(comm, ls, cfg.scheme, known_u, known_p, log=log,
                    zero_dofs=symmetry.zero_dofs(prob.mesh.nodes, prob.planes, prob.h))  # step matrix first
    with event("SSI_BEM_LagMats"):
        H, hinfo = lagmats.build(comm, ls.H, plan.Lx, ls.node_range, N, N, r1 - r0, cfg.lag_storage,
                                 prob.lag_fill)
        nt = prob.regions.n_t
        if nt:
            pl = PETSc.Vec().createMPI((PETSc.DECIDE, 3 * nt), bsize=3, comm=comm)
            tcol_loc = pl.getLocalSize() // 3
            pl.destroy()
            G, ginfo = lagmats.build(comm, ls.G, plan.Lx, ls.node_range, N, nt, tcol_loc, "dense")
        else:
            G = [None] * plan.Lx
    nev = ls.kernel_evaluations
    HI, GI = [], []
    for j in range(plan.k if plan.active else 0):
        lag, toff = plan.kernel_time(j)
        hb, gb = ls.assemble(monitor=False, lag_lo=lag, lag_hi=lag, toff=toff, single_from=single)
        nev += ls.kernel_evaluations
        HI.append(lagmats.build_one(comm, hb, lag, ls.node_range, N, N, r1 - r0, cfg.lag_storage,
                                    prob.lag_fill)[0])
        GI.append(lagmats.build_one(comm, gb, lag, ls.node_range, N, nt, tcol_loc, "dense")[0] if nt else None)
    ls.kernel_evaluations = nev
    t_asm = time.perf_counter() - t0
    mem_exact = comm.tompi4py().allreduce(sum(lagmats.mat_bytes(A) for A in H + G))
    mem_interp = comm.tompi4py().allreduce(sum(lagmats.mat_bytes(A) for A in HI + GI))
    mem = mem_exact + mem_interp
    ndense = sum(1 for i in hinfo if i[1] == "dense")
    nbaij = sum(1 for i in hinfo if i[1] == "baij")
    nsingle = sum(1 for i in hinfo if i[1] == "single")
    blocks = sum(i[2] for i in hinfo)
    fill = blocks / float(plan.Lx * N * N)
    if plan.active:
        printf(f"[ssi] memory: {plan.Lx} exact lags {mem_exact / 1e9:.3g} GB, {plan.k} interpolating "
               f"matrices {mem_interp / 1e9:.3g} GB (T_N = {plan.TN:.4g} s, T_L = {plan.TL:.4g} s)")
    single_txt = f", {nsingle} single-precision block-sparse" if nsingle else ""
    printf(f"[ssi] assembly {fmt_time(t_asm)}: {plan.Lx} exact lags ({ndense} dense, {nbaij} block-sparse"
           f"{single_txt}), "
           f"mean block fill {100 * fill:.1f}%, stored {mem / 1e9:.3g} GB, "
           f"{ls.kernel_evaluations:.3g} kernel evaluations, {ls.cache_hits} element pairs reused "
           f"(cache {ls.cache_bytes / 1e6:.3g} MB)")
    b, sub = _block_of(cfg, comm, H, G, HI, GI)
    march.set_lags(H, G, plan, HI, GI, block=b, sub=sub)
    _say_block(march)
    ls.H = ls.G = None   # the triplets are in the Mats now
    if cfg.get("lags_save"):
        from . import lagstore
        t1 = time.perf_counter()
        size = lagstore.save(cfg.lags_save, comm, march, lagstore.lag_key(cfg, prob, plan))
        printf(f"[ssi] lag matrices saved to {cfg.lags_save} ({size / 1e9:.3g} GB in "
               f"{fmt_time(time.perf_counter() - t1)}; -ssi_lags_load {cfg.lags_save} reuses them)")
    return march, {"t_asm": t_asm, "mem_exact": mem_exact, "mem_interp": mem_interp, "ndense": ndense,
                   "nbaij": nbaij, "nsingle": nsingle, "fill": fill, "mem": mem}


def _load_bem(cfg, comm, prob, plan, ls, known_u, known_p, log, t0):
    """Collective: build_bem with the matrices of -ssi_lags_load (checked in ``prepare``)."""
    PETSc = init()
    from . import lagstore
    N = prob.mesh.n_nodes
    nt = prob.regions.n_t
    tcol_loc = 0
    if nt:
        pl = PETSc.Vec().createMPI((PETSc.DECIDE, 3 * nt), bsize=3, comm=comm)
        tcol_loc = pl.getLocalSize() // 3
        pl.destroy()
    # (the file holds float32 values as doubles, PETSc's scalar: float32 again as each is read)
    A, H, G, HI, GI = lagstore.load(cfg.lags_load, comm, prob.lags_manifest, ls.node_range, N, nt, tcol_loc,
                                    single_from=int(cfg.lag_single_from),
                                    interp_lags=[plan.kernel_time(j)[0] for j in range(plan.k if plan.active else 0)])
    march = Marcher(comm, ls, cfg.scheme, known_u, known_p, log=log,
                    zero_dofs=symmetry.zero_dofs(prob.mesh.nodes, prob.planes, prob.h), A=A)
    if not nt:
        G = [None] * plan.Lx
    t_asm = time.perf_counter() - t0
    mpi = comm.tompi4py()
    mem_exact = mpi.allreduce(sum(lagmats.mat_bytes(M) for M in H + G))
    mem_interp = mpi.allreduce(sum(lagmats.mat_bytes(M) for M in HI + GI))
    kinds = dict(prob.lags_manifest["mats"])
    ndense = sum(1 for i in range(plan.Lx) if kinds.get(f"H{i + 1}") == "dense")
    from . import bsr
    nsingle = sum(1 for M in H if bsr.context(M) is not None and bsr.context(M).data.dtype == np.float32)
    nbaij = sum(1 for i in range(plan.Lx) if kinds.get(f"H{i + 1}") == "baij") - nsingle
    ls.kernel_evaluations = ls.cache_hits = 0
    ls.cache_bytes = 0.0
    printf(f"[ssi] lag matrices loaded from {cfg.lags_load} in {fmt_time(t_asm)} (no assembly): {plan.Lx} exact "
           f"lags ({ndense} dense, {nbaij} block-sparse" + (f", {nsingle} single-precision block-sparse" if nsingle
                                                               else "") + ")"
           + (f", {plan.k} interpolating matrices" if plan.active else "")
           + f", stored {(mem_exact + mem_interp) / 1e9:.3g} GB")
    b, sub = _block_of(cfg, comm, H, G, HI, GI)
    march.set_lags(H, G, plan, HI, GI, block=b, sub=sub)
    _say_block(march)
    ls.H = ls.G = None
    return march, {"t_asm": t_asm, "mem_exact": mem_exact, "mem_interp": mem_interp, "ndense": ndense,
                   "nbaij": nbaij, "nsingle": nsingle, "fill": float("nan"), "mem": mem_exact + mem_interp}


def _guard(cfg, prob, march, unorm, n):
    """Stop a clearly diverging run (same decision on every rank: the norm is
    a global reduction). Diverging: a non-finite norm, or after 20 steps a
    norm above guard_factor times the largest norm of the first half of the
    run so far. A loaded, damped (radiating) half-space cannot do that."""
    nrm = unorm[-1]
    pm = march.__dict__.setdefault("_prefix_max", [])      # running max of |u|: O(1) per step
    pm.append(max(pm[-1], nrm) if pm else nrm)
    ref = guard_reference(pm, n)
    if not guard_trips(nrm, ref, n, cfg.guard_factor):
        return
    rate = (np.log(nrm / ref) / (n - n // 2)) if (np.isfinite(nrm) and ref > 0) else float("inf")
    causes = []
    if march.scheme == "plain":
        causes.append(f"the plain scheme (eq. 6) is unstable for small beta = c_s dt / l (here {prob.beta[0]:.3g}; "
                      "runs/stability/README.md maps where): use -ssi_scheme stabilized")
    if prob.beta[0] < 0.3 or prob.beta[1] > 1.3:
        causes.append(f"beta = c dt / l spans [{prob.beta[0]:.2f}, {prob.beta[1]:.2f}], outside [0.3, 1.3]: "
                      "change -ssi_dt or the mesh")
    plan = getattr(march, "plan", None)
    if plan is not None:
        causes.append(f"lag interpolation from T_L = {plan.TL:.4g} s: a threshold below the Rayleigh "
                      "arrival (tau_L < 1.09) is inaccurate; raise -ssi_interp_tl")
    if not causes:
        causes.append("unknown (check the mesh and dt; -ssi_guard 0 disables this check)")
    exc = SSIError(f"the solution is diverging at step {n} (t = {n * prob.dt:.4g} s): |u| = {nrm:.3e}, "
                   f"{nrm / ref if ref > 0 else float('inf'):.3g} x the largest norm of the first half, growth "
                   f"rate {rate:.3g} per step; likely cause: {'; '.join(causes)}")
    exc.unorm = np.array(unorm)      # the history so far (-ssi_check_stability, runs/stability)
    raise exc


def traction_to_nodes(comm, prob, march):
    """AIJ mapping traction columns to a nodal traction field (for output)."""
    PETSc = init()
    reg = prob.regions
    if not reg.n_t:
        return None
    T = PETSc.Mat().createAIJ(size=((march.u_tmpl.getLocalSize(), 3 * prob.mesh.n_nodes),
                                    (march.p_tmpl.getLocalSize(), 3 * reg.n_t)), nnz=(3, 3), comm=comm)
    T.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    r0, r1 = T.getOwnershipRange()
    for k, node in enumerate(reg.tnode):
        for c in range(3):
            if r0 <= 3 * node + c < r1:
                T.setValue(3 * node + c, 3 * k + c, 1.0)
    T.assemble()
    return T


def _finish(cfg, comm, prob, out, res, status="completed", final=True):
    """Collective: write the receivers, attributes and run record; ``final``: close the output
    (else flush it: readable, still open)."""
    ev = event("SSI_IO")
    ev.begin()
    recd = None
    if res["u"] is not None:
        recd = {"points": prob.receivers, "t": res["t"], "u": res["u"]}
    attrs = {"problem": "bem", "cp": cfg.cp, "cs": cfg.cs, "rho": cfg.rho, "dt": cfg.dt,
             "scheme": cfg.scheme, "load_p0": cfg.load_p0, "load_history": cfg.load_history}
    groups = {"resultants": res["resultants"]} if res.get("resultants") is not None else None
    if cfg.mesh_patch and cfg.load_group == "load":
        attrs["load_patch"] = cfg.mesh_patch     # half-widths a,b of the loaded rectangle
    rec_ = provenance(cfg, comm, {"stats": res.get("stats", {})})
    (out.close if final else out.flush)(receivers=recd, attrs=attrs, record=rec_, status=status, groups=groups)
    ev.end()
    if not final:
        return
    if cfg.plot and comm.getRank() == 0 and recd is not None:
        from ..plot import receiver_plot
        receiver_plot(cfg.output, cfg)
