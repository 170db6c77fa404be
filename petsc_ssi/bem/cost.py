"""The BEM cost model: wall time per stage and peak memory of a run before it runs
(``petsc-ssi estimate -options_file ...``, ``app/estimate.py``; issue 6, part 4), the memory
estimate of the lag matrices (``lag_bytes``, ``peak_bytes``; ``LagSet.estimate_memory`` and the
memory check use them), the wave windows that bound the stored blocks (``pair_windows``), and the
time model of the time-blocked history sum (``choose_block``, ``history_block``).

The model counts the work of a run from the same set-up as the run itself
(mesh, regions, lags, interpolation plan, the per-lag block estimate of
``LagSet.estimate_memory``; no kernel is integrated) and turns the counts
into seconds and bytes with a few machine constants fitted to ``-log_view``
logs (``jobscripts/calibrate.py``). Per rank r of p (rows split as PETSc
splits them), with nb[l] the estimated non-zero 3x3 blocks of lag l in r's rows:

  assembly   a0 + a_blk * B_r + a_int * I_r           B_r = sum of nb over assembled lags
             + a_dense * D_r + a_sparse * S_r          (exact + interpolating); I_r pair-lags
             + a_lag * (L_x + k)                       integrated (pair_table); Mats: dense
                                                       bytes D_r, block-sparse blocks S_r, and
                                                       a cost per Mat (creation, collectives)
  factor     c_fac * N^1.5                              (sparse LU of the local step matrix)
  history    (HD_r / b_dense + HS_r / b_sparse)        bytes of lag matrices streamed over
             * (1 + sigma (m - 1))                     the run by per-step products (a dense
             + (c_op + c_op_mpi [p > 1]) * P_r          lag: 8 m N n_r B, block-sparse: 8 m + 4 B
             + (FD_r / r_panel_dense                    per block), m ranks per node sharing the
                + FS_r / r_panel_sparse)                memory bus; P_r matrix-vector products;
               * (1 + sigma_panel (m - 1))              FD, FS: flops of the time-blocked sum's
                                                       panel products (-ssi_history_block b,
                                                       -ssi_history_sub s; 2 per entry and state;
                                                       march.block_terms), dense and block-sparse,
                                                       each width's at its rate (the r_panel are
                                                       a 32-state panel's, panel_width_factor
                                                       scales them to b and s)
  solve      c_sol_nlogn * steps * N ln N * (1 + kappa (p - 1))   (solves with the factors: their fill
                                                       grows as N log N on a surface; N^1.5, the form
                                                       before, put a 49 923-DOF grid's solve at 247 ms
                                                       against 53.7 ms measured, N ln N puts it at 80 ms)
  setup      s0 + s1 * N * E_v / p                    (block estimate, free terms)
  rest       c_step * steps + c_main + c_plot [-ssi_plot]

with N the nodes (3N DOFs) and E_v the elements with symmetry images. Times
are the maximum over ranks; with more ranks per node than cores
(oversubscribed) every compute term is multiplied by ranks / cores.

Memory (peak of the processes, summed over ranks as -memory_view reports):
  p * m0 + gamma * max(rho_trip * (T + c_cache * C + p * m_asm),
                       max_k [Mats of lags <= k + T of lags > k] + G)
with T = 8 m + 4 B per block (m the entries of the block pattern, bem/bsr.py: 4 for H on a flat
surface, 9 in general; 4 m + 4 in single precision, -ssi_lag_single_from, as its Mats;
lag_bytes) the blocks of the assembly, C the bytes of the
element caches (pair_table: the distinct pair geometries each rank meets,
capped as the assembly caps them) and m_asm a per-rank transient. With the
cache shared between ranks (-ssi_cache_share, the default) I_r is 1/p of the
distinct pair-lags over all rows (each is integrated once, by its owner); the
exchange of the integrals between ranks is not modelled (measured: 0.5 s of
a 4.9 s assembly, medium case, 2 ranks).

It covers the BEM half-space (-ssi_problem bem; for ssi the BEM part only).
"""
import json
import os

import numpy as np

from ..petsc import SSIError
from ..sysmem import process_rss
from .windows import estimate_blocks

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))      # the package: petsc_ssi/
DEFAULT_CONSTANTS = os.path.join(HERE, "estimate_constants.json")

# Starting values (this code's 2-core development machine) if no table is found.
FALLBACK = {"a0": 0.5, "a_blk": 6e-7, "a_int": 0.0, "a_lag": 0.0, "c_cache": 1.0, "rho_trip": 1.0, "a_dense": 1.0e-9, "a_sparse": 5e-7, "c_fac": 1e-6, "b_dense": 16e9,
            "b_sparse": 9e9, "sigma": 0.4, "c_op": 2e-5, "c_op_mpi": 0.0, "c_sol_nlogn": 5e-7, "kappa": 0.3, "s0": 0.2,
            "s1": 3e-7, "c_step": 1e-3, "c_main": 0.7, "c_plot": 1.8, "m0": 0.15e9, "m_asm": 0.15e9,
            "gamma": 1.0, "r_panel_dense": 25e9, "r_panel_sparse": 15e9, "sigma_panel": 0.0}


def load_constants(path=""):
    path = path or DEFAULT_CONSTANTS
    if not os.path.exists(path):
        if path != DEFAULT_CONSTANTS:
            raise SSIError(f"-ssi_estimate_constants {path}: no such file")
        return dict(FALLBACK), "built-in starting values (no calibration table)"
    try:
        with open(path) as fh:
            d = json.load(fh)
        c = dict(FALLBACK)
        c.update({k: float(v) for k, v in d["constants"].items()})
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise SSIError(f"-ssi_estimate_constants {path}: not a constants table ({type(exc).__name__}: {exc})") from None
    return c, f"{os.path.relpath(path)} ({d.get('machine', '?')}, {d.get('fitted_from', '?')})"


def pair_table(prob, ls, L, chunk=64, rows=None):
    """Every (collocation node, element) pair that the assembly integrates for
    lags 1..L: (row, geometry key, first and last lag of its wave window). The
    key is the element's node coordinates relative to the collocation point,
    quantised as the assembly's element cache keys them, so equal keys are the
    pairs the cache integrates once (translated copies on a structured mesh).
    ``prob``: anything with mesh, mat and dt (a HalfSpace or a LagSet); ``rows``: the
    node rows looked at (default every node; ids in the table stay global)."""
    x = prob.mesh.nodes
    ids = np.arange(len(x)) if rows is None else np.asarray(rows, np.int64)
    VX, Vc, VR, Vh = ls.VX, ls.Vc, ls.VR, ls.Vh
    cp, cs, dt = prob.mat.cp, prob.mat.cs, prob.dt
    qinv = 1.0 / (1e-9 * float(Vh.min()))
    mult = np.random.default_rng(12345).integers(1, 2 ** 62, size=27, dtype=np.int64) | 1
    rows, keys, los, his = [], [], [], []
    for s in range(0, len(ids), chunk):
        xc = x[ids[s:s + chunk]]
        d = np.linalg.norm(xc[:, None, :] - Vc[None, :, :], axis=2)
        dmin = np.maximum(d - VR, 0.0)
        lo = np.maximum(1, np.floor(dmin / cp / dt).astype(np.int64) + 1)
        hi = np.minimum(L, np.floor((d + VR) / cs / dt).astype(np.int64) + 2)
        r, v = np.nonzero((dmin < cp * dt * L) & (hi >= lo))
        rel = np.rint((VX[v] - xc[r][:, None, :]) * qinv).astype(np.int64).reshape(len(v), 27)
        with np.errstate(over="ignore"):
            keys.append((rel * mult).sum(axis=1))
        rows.append(ids[s:s + chunk][r].astype(np.int32))
        los.append(lo[r, v].astype(np.int32))
        his.append(hi[r, v].astype(np.int32))
    if not rows:
        return np.zeros(0, np.int32), np.zeros(0, np.int64), np.zeros(0, np.int32), np.zeros(0, np.int32)
    return np.concatenate(rows), np.concatenate(keys), np.concatenate(los), np.concatenate(his)


def cache_counts(table, a, b, cap_floats, Lx, interp_lags=(), shared=None, stride=81):
    """Rows a..b-1 (one rank): the pair-lags it integrates (the element cache's
    misses, and every pair met after the cache is full) for the exact lags
    1..Lx and for each interpolating matrix (its own call, one lag), and the
    floats of the element cache of the exact lags. ``shared`` = (p, global
    distinct pair-lags of the exact lags, of the interpolating calls): the
    cache shared between p ranks, where each distinct geometry is integrated
    once, by its owner (1/p of them each); the rank still stores every
    geometry it meets, up to the cap. The pools take ``stride`` doubles a lag slot at most
    (assemble._compact: 9 m, m the entries of the block pattern); returns the lag slots stored."""
    rows, keys, lo, hi = table
    m = (rows >= a) & (rows < b) & (lo <= Lx)
    k, n = keys[m], (np.minimum(hi[m], Lx) - lo[m] + 1).astype(np.int64)
    _, first = np.unique(k, return_index=True)
    order = np.sort(first)                   # distinct geometries in the order met
    need = np.cumsum(n[order] * stride)
    stored = need <= cap_floats
    pool = float(need[stored][-1]) / stride if stored.any() else 0.0
    overflow = 0.0
    if not stored.all():                     # geometries met after the cache filled: every pair integrates
        cached = np.isin(k, k[order[stored]])
        overflow = float(n[~cached].sum())
    if shared is not None:
        p, g_exact, g_interp = shared
        return (g_exact * float(stored.mean() if len(stored) else 1.0) + g_interp) / p + overflow, pool
    integ = float(n[order[stored]].sum()) + overflow
    if len(interp_lags):
        m = (rows >= a) & (rows < b)
        _, first = np.unique(keys[m], return_index=True)
        lo_u, hi_u = lo[m][first], hi[m][first]
        for l in interp_lags:
            integ += float(np.count_nonzero((lo_u <= l) & (hi_u >= l)))
    return integ, pool


def global_distinct(table, Lx, interp_lags=()):
    """Pair-lags of the distinct geometries over all rows: the exact lags 1..Lx, and the interpolating
    calls (one lag each); what a cache shared by every rank integrates."""
    rows, keys, lo, hi = table
    m = lo <= Lx
    _, first = np.unique(keys[m], return_index=True)
    g_exact = float((np.minimum(hi[m][first], Lx) - lo[m][first] + 1).sum())
    _, first = np.unique(keys, return_index=True)
    lo_u, hi_u = lo[first], hi[first]
    g_interp = float(sum(np.count_nonzero((lo_u <= l) & (hi_u >= l)) for l in interp_lags))
    return g_exact, g_interp


class Counts:
    """The work of one run, counted from the set-up (no assembly).

    ``per_rank[p]``: a list over ranks of dicts of counts for p ranks."""

    def __init__(self, prob, plan, ls, ranks, limit, comm, assembly=True, ranges=None):
        """``assembly``: count the element caches' integrations (``pair_table``; the assembly term's,
        O(nodes x elements)); False for the time loop alone (the run's own prediction). ``ranges``:
        {p: [(a, b) per rank]} the node ranges of a partition already made (the run's), else cut here."""
        cfg = prob.cfg
        self.N = N = prob.mesh.n_nodes
        self.Ev = len(ls.Vc)
        self.nt = prob.regions.n_t
        self.steps = prob.n_steps
        self.L = prob.L
        self.mH, self.mG = ls.mH, ls.mG          # values a block (bem/bsr.py PATTERNS)
        self.active = bool(plan.active)
        self.Lx = plan.Lx
        self.k = plan.k if plan.active else 0
        self.interp_lags = [plan.kernel_time(j)[0] for j in range(self.k)]
        self.plot = bool(cfg.plot)
        self.stabilized = cfg.scheme.startswith("stabili")
        self.writes = snapshot_writes(cfg, self.steps)
        self.source_s = source_step_seconds(cfg)
        nimg = len(ls.Vc) // prob.mesh.n_cells
        Lmax = max([self.Lx] + self.interp_lags)
        # the node ranges of the ranks of every rank count, as the run cuts them (bem/partition.py)
        from . import partition
        w = None
        ranges = dict(ranges or {})
        if cfg.partition == "balanced" and max(ranks) > 1 and set(ranks) - set(ranges):
            w = partition.all_weights(comm, prob.mesh.nodes, ls.Vc, ls.VR, prob.mat, prob.dt, nimg,
                                      partition.lag_weights(self.Lx, self.L, self.stabilized, self.interp_lags),
                                      self.Lx, self.nt)
        self.ranges = {p: [tuple(int(v) for v in r) for r in ranges[p]] if p in ranges else
                       partition.balanced_ranges(w, p) if w is not None else partition.equal_ranges(N, p)
                       for p in ranks}
        jobs = [(p, r, a, b) for p in ranks for r, (a, b) in enumerate(self.ranges[p])]
        nb = self._blocks(prob, ls, jobs, Lmax, nimg, comm)
        self.cache = self._cache(prob, ls, jobs, Lmax, comm) if cfg.cache and assembly else {}
        total = nb[(ranks[0], 0)] * 0
        for r in range(ranks[0]):
            total = total + nb[(ranks[0], r)]
        self.nb_total = total
        # of them, the blocks H keeps in the flat pattern (a split H: a surface that is not one plane)
        self.flat_frac = flat_fraction(prob.mesh.nodes, ls, total, Lmax, prob.mat, prob.dt, nimg)
        # storage rule of lagmats (and the all-sparse fallback of check_memory)
        self.limit = limit
        used = np.r_[total[:self.Lx], [total[l - 1] for l in self.interp_lags]]
        self.single = single_lags(np.r_[np.arange(1, self.Lx + 1), self.interp_lags], int(cfg.lag_single_from))
        self.storage, self.fill = self._storage(cfg, used, limit)
        # the time-blocked history sum's block: the run's choice from these matrices' bytes
        tot = self.nb_total_used()
        mats, _, g = lag_bytes(tot, self.storage, self.single, N, N, self.nt, self.mH, self.mG, self.flat_of(tot))
        g = g * (tot > 0) * (self.nt > 0)
        self.block, self.sub = history_block(cfg, np.where(self.storage, mats, 0.0) * (tot > 0) + np.where(self.single, 0.0, g),
                                   np.where(self.storage, 0.0, mats) + np.where(self.single, g, 0.0),
                                   np.where(self.storage, 0.0, self.h_entries(tot))
                                   + np.where(self.single, g / (4.0 * self.mG + 4) * self.mG, 0.0))
        self.per_rank = {p: [self._rank(nb[(p, r)], b - a, p, self.cache.get((p, r))) for r, (a, b)
                             in enumerate(self.ranges[p])] for p in ranks}

    @staticmethod
    def _blocks(prob, ls, jobs, Lmax, nimg, comm):
        """Collective: {(p, r): blocks per lag} of every rank r of every rank count p (``jobs``: (p, r,
        first row, end row)), the jobs spread over the ranks of this process."""
        nb = {}
        for i, (p, r, a, b) in enumerate(jobs):
            if i % comm.getSize() == comm.getRank():
                rows = np.arange(a, b, dtype=np.int64)
                nb[(p, r)] = estimate_blocks(prob.mesh.nodes, rows, ls.Vc, ls.VR, Lmax, prob.mat, prob.dt, nimg)
        for part in comm.tompi4py().allgather(nb):
            nb.update(part)
        return nb

    def _cache(self, prob, ls, jobs, Lmax, comm):
        """Collective: {(p, r): counts} of the element cache of the exact lags' assembly (one cache per
        rank and call; ``cache_counts``), the jobs spread as in ``_blocks``."""
        cfg = prob.cfg
        table = pair_table(prob, ls, Lmax)
        g = global_distinct(table, self.Lx, self.interp_lags) if cfg.cache_share else None
        cc, out = {}, {}
        for i, (p, r, a, b) in enumerate(jobs):
            if i % comm.getSize() == comm.getRank():
                cc[(p, r)] = cache_counts(table, a, b, CACHE_MAX / 8, self.Lx, self.interp_lags,
                                          (p,) + g if g and p > 1 else None, stride=9 * max(self.mH, self.mG))
        for part in comm.tompi4py().allgather(cc):
            out.update(part)
        return out

    def _storage(self, cfg, used, limit):
        N = self.N
        f = used / float(N * N)
        fill = cfg.lag_fill
        if cfg.lag_storage == "auto":
            dense = (f > fill) & ~self.single
            if self.peak_rule(used, dense) > limit:
                dense_sp = np.zeros_like(dense)
                if self.peak_rule(used, dense_sp) <= limit:
                    return dense_sp, 1.01
            return dense, fill
        return np.full(len(used), cfg.lag_storage == "dense") & ~self.single, fill

    def peak_rule(self, used, dense, p=1):
        """check_memory's assembly-peak bound (LagSet.estimate_memory), for the
        storage decision the run will take."""
        N = self.N
        mats, trip, g = lag_bytes(used, dense, self.single, N, N, self.nt, self.mH, self.mG, self.flat_of(used))
        asm, rss = transient_bytes(used[:self.Lx].sum() / p, N, self.Lx, N / p, parts=True)
        asm_i = transient_bytes(max(list(used[self.Lx:]) + [0.0]) / p, N, 1, N / p, parts=True)[0] if self.k else 0.0
        return peak_bytes(mats, trip, g, asm * p, rss * p, n_exact=self.Lx, asm_interp=asm_i * p)

    def _rank(self, nb, nrows, p, cache=None):
        """Counts of one rank (``nb``: its blocks per lag, ``nrows``: its nodes,
        ``cache``: its integrated pair-lags and cache floats, None: no cache)."""
        N, Lx = self.N, self.Lx
        used = np.r_[nb[:Lx], [nb[l - 1] for l in self.interp_lags]]
        dense = self.storage
        nonempty = self.nb_total_used() > 0
        mat_bytes, trip, g_bytes = lag_bytes(used, dense, self.single, N, nrows, self.nt, self.mH, self.mG,
                                             self.flat_of(used))
        mat_bytes = mat_bytes * nonempty
        g_bytes = g_bytes * nonempty if self.nt else np.zeros(len(used))
        build = np.cumsum(mat_bytes) + (trip.sum() - np.cumsum(trip))
        # history: at step n the exact lags 2..min(Lx, n+1) (plain: n) and, once
        # lags beyond Lx are reached, the k interpolating matrices
        n = np.arange(1, self.steps + 1)
        from .partition import lag_uses
        uses = lag_uses(Lx, self.steps, self.stabilized, self.k)     # steps in which each stored matrix is used
        fl = {k: 0.0 for k in ("FDb", "FDs", "FSb", "FSs")}
        if self.block > 1:
            # the time-blocked sum (bem/march.py): a matrix takes part in a block's panel product when
            # one of the block's steps reads a state known at its start; the rest are per-step products.
            # The panel flops by width: the block's panels are b states wide, the sub-blocks' s (the
            # kernels' rates differ by 2-4x between them: panel_width_factor)
            uses, wb, ws = self._blocked_uses(n, used)
            entries = np.where(dense, mat_bytes / 8.0, self.h_entries(used)) * nonempty
            g_entries = self.mG * nrows * self.nt * nonempty         # (single: block-sparse, with the sparse)
            d_ent = entries * dense + g_entries * ~self.single
            s_ent = entries * ~dense + g_entries * self.single
            fl = {"FDb": float(np.sum(wb * 2.0 * d_ent)), "FDs": float(np.sum(ws * 2.0 * d_ent)),
                  "FSb": float(np.sum(wb * 2.0 * s_ent)), "FSs": float(np.sum(ws * 2.0 * s_ent))}
        fd, fs = fl["FDb"] + fl["FDs"], fl["FSb"] + fl["FSs"]
        hd = float(np.sum(uses * (mat_bytes + g_bytes) * dense))
        hs = float(np.sum(uses * mat_bytes * ~dense) + np.sum(uses * g_bytes * ~dense))
        prods = float(np.sum(uses * nonempty) * (2 if self.nt else 1))
        # integrated pair-lags: with the cache its misses; without, every pair (~ blocks / 4)
        integ, pool = cache if cache is not None else (float(used.sum()) / 4.0, 0.0)
        return {"B": float(used.sum()), "I": integ, "C": 8.0 * 9 * (self.mH + self.mG) * pool, "D": float(np.sum(mat_bytes * dense)),
                "S": float(np.sum(used * ~dense * nonempty)), "HD": hd, "HS": hs, "P": prods, "FD": fd, "FS": fs, **fl,
                "mats": float(mat_bytes.sum() + g_bytes.sum()), "trip": float(trip.sum()),
                "build": float(build.max() + g_bytes.sum()), "rows": nrows}

    def _blocked_uses(self, n, used):
        """(per-step uses, summed block-panel width, summed sub-block-panel width) of each stored matrix
        with blocks of ``self.block`` steps and sub-blocks of ``self.sub`` (``march.block_terms``: the
        states a block's or a sub-block's start knows go into its panel product, the others into a
        product of the step)."""
        key = (len(n), len(used))
        if getattr(self, "_uses", (None,))[0] == key:      # the same for every rank and rank count
            return self._uses[1]
        from .march import block_terms
        b, s, Lx = self.block, self.sub, self.Lx
        steps_in, wblk, wsub = np.zeros(len(used)), np.zeros(len(used)), np.zeros(len(used))
        for j in range(2, Lx + 1):
            steps_in[j - 1], wblk[j - 1], wsub[j - 1] = block_terms(n, [j], b, s, self.stabilized)
        if self.k:
            steps_in[Lx:], wblk[Lx:], wsub[Lx:] = block_terms(n, range(Lx + 1, self.L + 1), b, s, self.stabilized)
        self._uses = (key, (steps_in, wblk, wsub))
        return steps_in, wblk, wsub

    def nb_total_used(self):
        t = self.nb_total
        return np.r_[t[:self.Lx], [t[l - 1] for l in self.interp_lags]]

    def flat_of(self, used):
        """Of ``used`` blocks of the stored matrices (exact lags, then interpolating), those H keeps in the
        flat pattern (``flat_fraction``), or None (not split)."""
        f = self.flat_frac
        return None if f is None else used * np.r_[f[:self.Lx], [f[l - 1] for l in self.interp_lags]]

    def h_entries(self, used):
        """Values H stores in ``used`` blocks of the stored matrices (a split H: 4 a flat block)."""
        flat = self.flat_of(used)
        return self.mH * used - (0.0 if flat is None else (self.mH - 4.0) * flat)

    def lag_bytes(self):
        return sum(r["mats"] for r in self.per_rank[min(self.per_rank)])


def features(cnt, p, q, cores):
    """Model terms for p ranks, q per node, ``cores`` per node: the maxima over
    ranks of each count, the oversubscription factor and the concurrency m."""
    rk = cnt.per_rank[p]
    mx = {key: max(r[key] for r in rk) for key in ("B", "I", "D", "S", "HD", "HS", "P", "FD", "FS",
                                                   "FDb", "FDs", "FSb", "FSs")}
    qn = min(q, p)
    over = max(1.0, qn / float(cores))
    m = min(qn, cores)
    return mx, over, m


# A field snapshot (u and p into the HDF5 file and its XDMF) [s], which the fitted constants do not see:
# SNAPSHOT_S + SNAPSHOT_NODE_S per soil node. Measured 2026-12-02 on the development machine (2 cores, idle): the
# event SSI_IO of the time loop over its calls, -ssi_output_stride 1, 1 m grids of 4 x 4 to 16 x 16 elements
# (81-1089 nodes), dense and toeplitz stores, 1 and 2 ranks: 1.1-1.2 ms a snapshot at 81 nodes, 1.7 ms at 625,
# 1.4-1.8 ms at 1089 (`mpirun -n 2 petsc-ssi -ssi_problem bem -ssi_mesh_size 12,12 -ssi_mesh_h 1 -ssi_mesh_patch
# 1,1 -ssi_load_group load -ssi_dt 0.0025 -ssi_t_end 0.25 -ssi_output_stride 1 -log_view`). The 14 ms of an earlier
# measurement (a loop of 0.3 s with stride 0, 1.7 s with stride 1, before the output's parts) put a small
# case's default-stride loop at 1.49 s against 0.23 s measured. It dominates small cases only.
SNAPSHOT_S = 1.1e-3
SNAPSHOT_NODE_S = 1e-6          # (6e-7 on 2026-12-02, 1.2e-6 on 2026-12-03 at 1089-2401 nodes: the file system's hour)

# A seismic wave's work a step beside the history sum, the solve and c_step [s]: the free field on the nodes
# (the total field u_sc + u_ff of the records, halfspace.total_field) and a massless footing's correction
# (sources/rigid.py). 0.5-0.9 ms a step on 1 m grids of 12 x 12 and 24 x 24 elements (2026-12-02) and 0.3-1.2 ms
# on 8 x 8 and 16 x 16 (2026-12-03, jobscripts/toeplitz_loop_check.py's SV cases against its load cases).
SEISMIC_STEP_S = 6e-4


def source_step_seconds(cfg):
    """Seconds a step the run's sources add to the loop beside c_step: SEISMIC_STEP_S under -ssi_seismic."""
    return SEISMIC_STEP_S if str(cfg.get("seismic", "none") or "none").lower() != "none" else 0.0


def snapshot_seconds(n_nodes):
    """Seconds of one field snapshot of a soil surface of ``n_nodes`` nodes (SNAPSHOT_S, SNAPSHOT_NODE_S)."""
    return SNAPSHOT_S + SNAPSHOT_NODE_S * float(n_nodes)


def snapshot_writes(cfg, steps):
    """The field snapshots of a loop of ``steps`` steps (-ssi_output_stride; 0: none)."""
    stride = int(cfg.get("output_stride", 0) or 0)
    return (int(steps) // stride) if stride > 0 else 0


def bem_solve_seconds(c, N, p):
    """Seconds of one solve with the step matrix's factors on p ranks (N soil nodes): c_sol_nlogn N ln N
    (1 + kappa (p - 1)), the factors' fill on a surface mesh (nested dissection: N log N entries)."""
    return c["c_sol_nlogn"] * N * np.log(max(N, 2)) * (1 + c["kappa"] * (p - 1))


def loop_terms(cnt, c, p, q, cores):
    """Seconds of the BEM time loop on p ranks, q per node, ``cores`` per node (dict: history, solve,
    step, snapshots, loop): the history sums (streamed bytes, products, panel flops), the solves with
    the step matrix's factors, c_step (and a seismic wave's ``source_step_seconds``) per step and
    ``snapshot_seconds`` per field snapshot. The one model of the
    loop that ``petsc-ssi estimate`` (``predict``) and the run's own first line
    (``HalfSpace.check_memory``) both evaluate (issue 43: they had been two code paths)."""
    mx, over, m = features(cnt, p, q, cores)
    t = {"history": over * ((mx["HD"] / c["b_dense"] + mx["HS"] / c["b_sparse"]) * (1 + c["sigma"] * (m - 1))
                            + (c["c_op"] + (c["c_op_mpi"] if p > 1 else 0.0)) * mx["P"]
                            + panel_seconds(mx, cnt.block, cnt.sub, c, m)),
         "solve": cnt.steps * bem_solve_seconds(c, cnt.N, p),
         "step": (c["c_step"] + cnt.source_s) * cnt.steps,
         "snapshots": snapshot_seconds(cnt.N) * cnt.writes}
    t["loop"] = t["history"] + t["solve"] + t["step"] + t["snapshots"]
    return t


def panel_width_factor(w, kind):
    """The panel kernel's rate at w states relative to its rate at 32 (PANEL_DENSE_GFPS and
    PANEL_SPARSE_GFPS, measured on one core by jobscripts/dgemm_rate.py; clamped outside 8-32 states):
    a sub-block's panel of 12 states runs at 0.42 of a block's of 32 (block-sparse)."""
    table = PANEL_DENSE_GFPS if kind == "dense" else PANEL_SPARSE_GFPS
    return float(np.interp(w, PANEL_B, table)) / table[-1]


def panel_seconds(mx, b, s, c, m=1):
    """Seconds of the time-blocked history sum's panel products (event SSI_BEM_HistPanel) from their
    flops by kind and width (``mx``: FDb, FDs, FSb, FSs of Counts): r_panel_dense and r_panel_sparse are
    the rates of panels 32 states wide, scaled to b and s by ``panel_width_factor``; m ranks of a node
    slow each other by 1 + sigma_panel (m - 1) (the shared memory bus and caches)."""
    rd, rs = c["r_panel_dense"], c["r_panel_sparse"]
    t = (mx["FDb"] / (rd * panel_width_factor(b, "dense")) + mx["FDs"] / (rd * panel_width_factor(s, "dense"))
         + mx["FSb"] / (rs * panel_width_factor(b, "sparse")) + mx["FSs"] / (rs * panel_width_factor(s, "sparse")))
    return t * (1 + c.get("sigma_panel", 0.0) * (m - 1))


def loop_model(t, steps, lags):
    """k -> the seconds of the first k steps of a loop of ``steps`` steps whose terms are ``t``
    (``loop_terms``): the history sum grows with the lags in use (step n reads min(n, L) of the
    ``lags`` L), the rest is the same each step. The progress line compares the measured time with it."""
    L = max(int(lags), 1)

    def used(k):
        ramp = min(k, L)
        return ramp * (ramp + 1) / 2.0 + max(k - L, 0) * L

    total = max(used(steps), 1.0)
    rest = (t["solve"] + t["step"] + t["snapshots"]) / max(steps, 1)
    return lambda k: t["history"] * used(k) / total + rest * k


def predict(cnt, c, p, q, cores):
    """Seconds per stage and bytes for p ranks (dict)."""
    mx, over, m = features(cnt, p, q, cores)
    N15 = cnt.N ** 1.5
    t = {}
    t["setup"] = c["s0"] + c["s1"] * cnt.N * cnt.Ev / p
    t["assembly"] = c["a0"] + over * (c["a_blk"] * mx["B"] + c["a_int"] * mx["I"] + c["a_dense"] * mx["D"]
                                      + c["a_sparse"] * mx["S"] + c["a_lag"] * (cnt.Lx + cnt.k))
    t["factor"] = c["c_fac"] * N15
    t.update(loop_terms(cnt, c, p, q, cores))
    t["total"] = t["setup"] + t["assembly"] + t["factor"] + t["loop"] + c["c_main"] + (c["c_plot"] if cnt.plot else 0)
    rk = cnt.per_rank[p]
    asm = lambda r: c["rho_trip"] * (r["trip"] + c["c_cache"] * r["C"] + c["m_asm"])
    t["peak_bytes"] = p * c["m0"] + c["gamma"] * max(sum(asm(r) for r in rk), sum(r["build"] for r in rk))
    t["peak_rank_bytes"] = max(c["m0"] + c["gamma"] * max(asm(r), r["build"]) for r in rk)
    t["lag_bytes"] = sum(r["mats"] for r in rk)
    return t


CACHE_MAX = 512 << 20


def row_work_bytes(n_nodes, lag_hi):
    """A bound of the bytes one row's work may take in the assembly kernel (the integrals of its pairs
    outside the element cache, 9 m doubles a lag slot per pool, in arrays that grow by doubling)."""
    return 96.0 * 2 * n_nodes * max(lag_hi, 1) * 0.6


def chunk_rows(n_nodes, lag_hi, n_rows):
    return int(max(1, min(64, 256e6 // row_work_bytes(n_nodes, lag_hi), n_rows // 20 + 1)))


def flat_fraction(xnodes, ls, total, L, mat, dt, n_images):
    """Per lag 1..L the fraction of H's estimated blocks (``total``, all rows) it keeps in the flat pattern
    when split (``ls.split``: a surface that is not one plane, ``lagset.SplitBuckets``): the pairs whose
    point lies in the element's horizontal plane (``windows.estimate_blocks`` with ``plane_z``), or None."""
    if not getattr(ls, "split", False):
        return None
    from .windows import plane_heights
    nbf = estimate_blocks(xnodes, np.arange(len(xnodes)), ls.Vc, ls.VR, L, mat, dt, n_images,
                          plane_z=plane_heights(ls.VX, n_images))
    return np.where(total > 0, nbf / np.maximum(total, 1e-300), 0.0)


def lag_bytes(used, dense, single, n_cols, n_rows, n_t, mH=9, mG=9, flat=None):
    """Per stored matrix (arrays over them): (bytes of its Mat, of its assembly buckets, of its G),
    for ``used`` blocks in ``n_rows`` node rows of ``n_cols`` columns, each block holding the ``mH``
    entries of H's pattern (bem/bsr.py PATTERNS: 9, or 4 on a flat surface; G's ``mG``: 9 or 5):
    dense 8 mH B per block of the whole row block, block-sparse 8 mH + 4 B per stored block (the
    values, an int32 column: 76 B full, 36 B flat), single precision (``single``:
    -ssi_lag_single_from) 4 mH + 4 B whatever the fill; the buckets take the same bytes (their 15 %
    headroom is allocated but never touched, so not resident); G (the ``n_t`` traction columns)
    dense (8 mG B a block), or 4 mG + 4 B a block single. ``flat``: of the ``used`` blocks, those a split H
    keeps in the flat pattern (4 values: lagset.SplitBuckets, an excavated surface; a dense lag is merged,
    mH a block), or None."""
    single = np.asarray(single, bool)
    dense = np.asarray(dense, bool) & ~single
    fewer = 0.0 if flat is None else (mH - 4.0) * np.asarray(flat, float)     # values the flat blocks leave out
    mats = np.where(single, (4.0 * mH + 4) * used - 4.0 * fewer,
                    np.where(dense, 8.0 * mH * n_cols * n_rows, (8.0 * mH + 4) * used - 8.0 * fewer))
    trip = np.where(single, (4.0 * mH + 4) * used - 4.0 * fewer, (8.0 * mH + 4) * used - 8.0 * fewer)
    g = np.where(single, 4.0 * mG + 4, 8.0 * mG) * n_rows * max(n_t, 1)
    return mats, trip, g


def single_lags(lags, single_from):
    """Mask over ``lags`` (lag indices of the stored matrices): kept in single precision."""
    lags = np.asarray(lags)
    return (lags >= single_from) if single_from > 0 else np.zeros(lags.shape, bool)


def transient_bytes(blocks, n_nodes, lags, n_rows, cache=None, parts=False):
    """Bytes a rank holds beside the blocks and Mats: while it assembles, the element cache
    (``cache`` bytes as counted from the pair geometries, ``LagSet.cache_estimate``, or without it
    the bound of 324 B per block of its rows; each of its two pools capped at CACHE_MAX) and one
    row's work (the integrals of its pairs the cache does not hold, bounded by ``row_work_bytes``; the
    kernel writes the blocks where they are kept, assemble.assemble_rows); throughout, the process
    as it stands (resident size now, measured). ``parts``: (assembly-only bytes, process bytes), else
    their sum."""
    cache = min(2.0 * CACHE_MAX, 324.0 * blocks if cache is None else 2.0 * cache)   # pools grow by doubling
    row = row_work_bytes(n_nodes, lags)
    return (cache + row, process_rss()) if parts else cache + row + process_rss()


def peak_bytes(mats, trip, g, asm, rss, n_exact=None, asm_interp=0.0):
    """The memory check's peak (bytes, all ranks; ``LagSet.estimate_memory`` and ``petsc-ssi
    estimate``'s storage rule): 1.1 x the largest of the phases, with G (``g``) and the process
    (``rss``) throughout: assembling the exact lags (their blocks ``trip`` of the first ``n_exact``
    matrices, with the element cache and a chunk, ``asm``); building their Mats (``mats`` of lags
    <= k and blocks of lags > k); assembling each interpolating matrix after them (the exact Mats,
    the interpolating ones before it, its blocks, its own cache and chunk, ``asm_interp``)."""
    mats, trip = np.asarray(mats, float), np.asarray(trip, float)
    n = len(mats) if n_exact is None else int(n_exact)
    me, te = mats[:n], trip[:n]
    phases = [te.sum() + asm]
    if n:
        phases.append(float((np.cumsum(me) + (te.sum() - np.cumsum(te))).max()))
    mi, ti = mats[n:], trip[n:]
    for j in range(len(mi)):
        phases.append(me.sum() + mi[:j].sum() + ti[j] + asm_interp)
    return 1.1 * (max(phases) + float(np.sum(g)) + rss)


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
                 sparse_values=None, sub=0):
    """(b, s): the steps per block and per sub-block that minimise the modelled time per step of the
    history sum, from the bytes of each stored matrix (index 0: lag 1, ..., then the interpolating
    ones, taken as the lags that follow; dense and block-sparse apart): in a block of a run long
    enough to reach every lag (``march.block_terms``), its panel products at the rates above for
    their widths (2 flops per stored value and state) and the per-step products, streamed. b = 1
    streams every matrix every step. ``sparse_values``: the stored values of the block-sparse matrices
    (2 flops each per state; default 9 per 76 B, full double blocks); ``sub``: a fixed sub-block size (0: chosen too). Step by step is an
    outcome only when 1 is a candidate: a user's -ssi_history_block b (candidates (b,)) is kept."""
    from .march import block_terms
    d = np.asarray(dense_bytes, float)
    s = np.asarray(sparse_bytes, float)
    sv = s * 9.0 / 76.0 if sparse_values is None else np.asarray(sparse_values, float)
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
                        t += cnt * w * (d[i] * 2 / 8 / rd + sv[i] * 2 / rs)
                t += steps * every[i] / (STREAM_GBPS * 1e9)
            t /= b
            if t < best_t or best is None:
                best, best_t = (b, sub_b), t
    return best


def history_block(cfg, dense_bytes=None, sparse_bytes=None, sparse_values=None):
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
                        candidates=(b,) if b else (1, 2, 4, 8, 12, 16, 24, 32), sparse_values=sparse_values,
                        sub=sub)



