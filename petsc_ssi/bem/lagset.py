"""The lag set of a BEM run: material, regions, the node partition, the memory estimate and the
assembly of the lag matrices (``LagSet``), and the per-lag block buckets it fills.

Collective functions say so. Rows (collocation DOFs, 3 per node) are split by
the ownership ranges of a PETSc Vec of size 3N with block size 3; each rank
computes only the rows it owns, with no gather of matrices.
"""
import os

import numpy as np

from ..petsc import SSIError, collective, printf
from ..monitor import Progress, event
from .cost import (CACHE_MAX, row_work_bytes, chunk_rows, single_lags, lag_bytes, transient_bytes, peak_bytes,
                   pair_table, cache_counts)
from .windows import bounding_spheres, estimate_blocks, plane_heights, candidates
from . import symmetry
from . import packs
# The compiled kernels (.bsr, .assemble: numba, 0.25 s to import) are imported where a LagSet uses them, so
# that runs refused on their options, structure-only runs and the post tools start without numba
# (tests/test_startup.py).


class Material:
    def __init__(self, cp, cs, rho):
        self.cp, self.cs, self.rho = float(cp), float(cs), float(rho)
        self.mu = rho * cs ** 2
        self.lam = rho * cp ** 2 - 2 * self.mu
        k2 = (cp / cs) ** 2
        self.nu = (k2 - 2.0) / (2.0 * (k2 - 1.0))


class Regions:
    """Traction columns: nodes of the loaded and of the prescribed-displacement
    element sets. Tractions are continuous inside a region and discontinuous
    across its boundary (a traction-free neighbour has zero traction at a
    shared node), so each region numbers its own nodes."""

    def __init__(self, mesh, load_elems=(), disp_elems=()):
        load_elems = np.unique(np.asarray(load_elems, np.int64))
        disp_elems = np.unique(np.asarray(disp_elems, np.int64))
        both = np.intersect1d(load_elems, disp_elems)
        if both.size:
            raise SSIError(f"{both.size} elements are both loaded and have a prescribed displacement")
        self.load_elems, self.disp_elems = load_elems, disp_elems
        self.load_nodes = np.unique(mesh.cells[load_elems]) if load_elems.size else np.zeros(0, np.int64)
        self.disp_nodes = np.unique(mesh.cells[disp_elems]) if disp_elems.size else np.zeros(0, np.int64)
        self.n_load = len(self.load_nodes)
        self.n_disp = len(self.disp_nodes)
        self.n_t = self.n_load + self.n_disp
        tcols = -np.ones(mesh.cells.shape, np.int64)
        for elems, nodes, off in ((load_elems, self.load_nodes, 0),
                                  (disp_elems, self.disp_nodes, self.n_load)):
            if elems.size:
                lut = -np.ones(mesh.n_nodes, np.int64)
                lut[nodes] = off + np.arange(len(nodes))
                tcols[elems] = lut[mesh.cells[elems]]
        self.tcols = tcols
        self.tnode = np.concatenate([self.load_nodes, self.disp_nodes])  # node of each traction column


_KERNELS_LOADED = []


def load_kernels():
    """Load the assembly's compiled kernels into this process (once; from the numba cache, or
    compiled): a tiny assembly on one process. The memory check measures the process after it, so
    that the code the kernels bring is counted."""
    if _KERNELS_LOADED:
        return
    from ..petsc import init
    from ..mesh.surface import grid
    PETSc = init()
    mesh = grid(2.0, 2.0, 1.0, (1.0, 1.0))
    opts = {"gauss": 2, "singular_order": 4, "subdivisions": 1, "near_factor": 0.0, "max_subdivisions": 1,
            "cache": True}
    from .. import numba_cache_warm
    if not numba_cache_warm() and not os.environ.get("PETSC_SSI_WARMUP"):
        announce_compile()
    LagSet(PETSc.COMM_SELF, mesh, Material(548.0, 316.0, 2000.0), 0.005, 2,
           Regions(mesh, load_elems=mesh.groups["load"]), [], opts).assemble(quiet=True)
    _KERNELS_LOADED.append(True)


_ANNOUNCED = []


def announce_compile():
    """Say once per process that the kernels compile now (a cold numba cache)."""
    if not _ANNOUNCED:
        _ANNOUNCED.append(True)
        import petsc_ssi
        printf("[ssi] compiling the BEM kernels with numba (first run of this checkout, "
               f"{os.path.dirname(petsc_ssi.__file__)}, on this machine: ~1 min; cached in "
               f"{os.environ.get('NUMBA_CACHE_DIR')}; 'python -m petsc_ssi.app.warmup' or 'make deps' does it ahead)")


class _NoEvent:
    def begin(self):
        pass

    def end(self):
        pass


class Buckets:
    """The blocks of the local rows (``rows``, of ``n_nodes``) by lag (1-based), as block CSR being
    built where they are kept: per lag one array of columns (int32) and one of blocks (blocks x
    ``m``: the entries of the matrix's pattern, ``bsr.PATTERNS``), and the blocks per (lag, row).
    The assembly kernel writes each row's blocks straight into them (``assemble.emit_row``, through
    the typed lists ``out()``), rows ascending and columns sorted, so no sort, concatenation or copy
    follows; ``add`` does the same for triplets given from Python. ``csr(l)`` gives (indptr, cols,
    vals), ``peek(l)`` (rows, cols, full 3x3 blocks with the free term); ``take_csr(l)`` frees the lag.
    Lag 1 of H carries the free term apart (``free``, ``diag``). The arrays are allocated at
    ``capacity[l - 1]`` blocks (the memory estimate's count, with headroom: allocated, never touched,
    not resident) and grow by half when a row finds no room (in the kernel, ``assemble._room``): each
    page is written once, in place. ``small``: every page of them small (madvise MADV_NOHUGEPAGE:
    ``petsc.lag_small_pages``, -ssi_huge_pages auto on a VM that hands free memory back to its host,
    or off; an array the kernel grows is numba's and gets the system's default); otherwise numpy's advice holds (huge pages unless ``-ssi_huge_pages off``), except from
    ``SMALL_FROM`` of the ``expected`` blocks on (small pages: the 2 MB page holding a lag's last
    block is not faulted in whole: 0.12-0.14 GB a rank counted on the paper case, its measured peak
    0.18 GB lower over the node)."""

    GROW = 1.5
    TRIM = 0.5            # a lag using less of its array (a growth's overshoot) is copied to its size when taken;
                          # the estimate's 15 % headroom is never touched, so not resident: kept, no copy

    SMALL_FROM = 0.85     # of the expected blocks: a lag array's pages from there on are small (sysmem.small_pages_from)

    def __init__(self, L, rows, n_nodes, capacity=None, single_from=0, m=9, free=None, expected=None,
                 small=False):
        self.L, self.rows, self.nloc = L, np.asarray(rows, np.int64), len(rows)
        self.m = int(m)                         # values a block: bsr.PATTERNS (9: full 3x3)
        self.free = None if free is None else np.asarray(free, float).reshape(-1, 3, 3)   # lag 1's free term
        self.single_from = int(single_from)     # lags >= this (> 0) keep their blocks in float32
        if self.single_from in (1, 2):
            raise ValueError("Buckets: lags 1 and 2 (the step matrix) stay double (single_from 0 or >= 3)")
        self.loc = np.full(n_nodes, -1, np.int64)
        self.loc[self.rows] = np.arange(self.nloc)
        self.counts = np.zeros((L + 1, max(self.nloc, 1)), np.int64)
        self.n = np.zeros(L + 1, np.int64)      # blocks each lag holds (written by the kernel)
        cap = np.zeros(L + 1, np.int64)
        if capacity is not None:
            cap[1:] = np.asarray(capacity, np.int64)[:L]
        exp = np.zeros(L + 1)
        if expected is not None:
            exp[1:] = np.asarray(expected, float)[:L]
        from .assemble import new_lists, set_lag
        from ..sysmem import small_pages_from
        self._c, self._v, self._v32 = new_lists(L + 1, self.m)
        for lag in range(L + 1):
            k = int(cap[lag])
            if k:
                single = self.dtype(lag) == np.float32
                c = np.empty(k, np.int32)
                v = np.empty((0 if single else k, self.m))
                v32 = np.empty((k if single else 0, self.m), np.float32)
                if small or exp[lag] > 0:   # all small, or the last stored block's: not a whole 2 MB page
                    b = 0 if small else int(self.SMALL_FROM * exp[lag])
                    for a in (c, v, v32):   # (an array under 2 MB holds no whole huge page: left alone)
                        if a.shape[0] and (a.nbytes >= 2 << 20 or not small):
                            small_pages_from(a, b * (a.nbytes // a.shape[0]))
                set_lag(self._c, self._v, self._v32, lag, c, v, v32)

    def out(self):
        """The kernel's view (``assemble.emit_row``): (columns, values, float32 values, fill, counts,
        single_from)."""
        return (self._c, self._v, self._v32, self.n, self.counts, self.single_from)

    def add(self, row, lag, col, val):
        """Append triplets (rows ascending, any order within a row; ``val`` (n, m)) as the kernel does."""
        from .assemble import emit_row
        row, lag, col = np.asarray(row, np.int64), np.asarray(lag, np.int64), np.asarray(col, np.int64)
        val = np.ascontiguousarray(val, float).reshape(len(row), self.m)
        for r in np.unique(row):
            k = np.nonzero(row == r)[0]
            k = k[np.lexsort((col[k], lag[k]))]
            emit_row(len(k), lag[k], col[k], val[k], int(self.loc[r]), self.out())

    def dtype(self, lag):
        """The value type lag ``lag`` is kept in: float32 from ``single_from`` on (-ssi_lag_single_from)."""
        return np.float32 if 0 < self.single_from <= lag else np.float64

    def csr(self, lag):
        """(indptr over the rows in their order, columns int32, blocks) of one lag (views)."""
        n = int(self.n[lag])
        indptr = np.zeros(self.nloc + 1, np.int64)
        np.cumsum(self.counts[lag, :self.nloc], out=indptr[1:])
        from .assemble import get_lag
        c, v, v32 = get_lag(self._c, self._v, self._v32, lag)
        return indptr, c[:n], (v32 if self.dtype(lag) == np.float32 else v)[:n]

    def diag(self, lag):
        """The free term of the local rows if lag ``lag`` carries it (lag 1 of H), else None."""
        return self.free if (lag == 1 and self.free is not None) else None

    def peek(self, lag):
        """(rows, columns, full 3x3 blocks) of one lag, the free term added to the diagonal blocks of
        lag 1 (a block made where the kernel's is absent), in (row, column) order: the blocks as the
        collocation equations have them (the step matrix, tests)."""
        from .bsr import expand
        indptr, c, v = self.csr(lag)
        rows = np.repeat(self.rows, np.diff(indptr))
        v = expand(v, self.m).astype(float)
        F = self.diag(lag)
        if F is None:
            return rows, c, v
        loc = self.loc[rows]
        d = c == rows
        v[d] += F[loc[d]]                                   # (the kernel's sum, then the free term)
        miss = np.ones(self.nloc, bool)
        miss[loc[d]] = False
        rows = np.r_[rows, self.rows[miss]]
        c = np.r_[c, self.rows[miss]].astype(np.int32)
        v = np.concatenate([v, F[miss]])
        o = np.lexsort((c, rows))
        return rows[o], c[o], v[o]

    def take_csr(self, lag):
        """``csr(lag)``; the lag is no longer held here (its arrays copied to size when mostly unused)."""
        indptr, c, v = self.csr(lag)
        from .assemble import get_lag, set_lag
        if len(c) < self.TRIM * len(get_lag(self._c, self._v, self._v32, lag)[0]):
            c, v = c.copy(), v.copy()
        set_lag(self._c, self._v, self._v32, lag, np.empty(0, np.int32), np.empty((0, self.m)),
                np.empty((0, self.m), np.float32))
        self.n[lag] = 0
        self.counts[lag] = 0
        return indptr, c, v

    def count(self, lag):
        return int(self.n[lag])


class SplitBuckets:
    """H's blocks of a surface that is not one plane (an excavation) in two ``Buckets``: ``flat``, the
    blocks whose entries outside the flat pattern (bsr.H4) are exact zeros, 4 values each (every block
    whose pairs all lie in one horizontal plane: the ground, the pit's bottom), and ``full``, the others
    (9 values). The assembly kernel sorts each row's blocks between them (``assemble._emit_split``).
    Reads as one Buckets where the lag's blocks are wanted whole (``count``, ``csr``, ``peek``, ``diag``);
    ``parts`` gives the two block CSRs of a lag for its Mat (``lagmats.build``)."""

    def __init__(self, full, flat):
        self.full, self.flat = full, flat
        self.m = full.m
        self.rows, self.nloc, self.loc = full.rows, full.nloc, full.loc

    def count(self, lag):
        return self.full.count(lag) + self.flat.count(lag)

    def diag(self, lag):
        return self.full.diag(lag)

    def dtype(self, lag):
        return self.full.dtype(lag)

    def csr(self, lag):
        """``Buckets.csr`` of the whole lag: (indptr, columns, (blocks, 9)), the parts merged (a copy)."""
        from .lagmats import merged
        return merged([self.full.csr(lag), self.flat.csr(lag)], [self.full.m, self.flat.m], self.nloc)

    def parts(self, lag):
        """[(block CSR, pattern)] of lag ``lag``, the full part first (it carries the free term); the lag
        is no longer held here."""
        return [(self.full.take_csr(lag), self.full.m), (self.flat.take_csr(lag), self.flat.m)]

    def peek(self, lag):
        """``Buckets.peek`` of both parts together: (rows, columns, full 3x3 blocks), the free term added,
        in (row, column) order (a block is in one part; the free term's diagonal block may meet a flat
        kernel block: their sum, as Buckets.peek adds them)."""
        r1, c1, v1 = self.full.peek(lag)
        r2, c2, v2 = self.flat.peek(lag)
        r, c, v = np.r_[r1, r2], np.r_[c1, c2].astype(np.int64), np.concatenate([v1, v2])
        key, inv = np.unique(r * len(self.loc) + c, return_inverse=True)
        out = np.zeros((len(key), 3, 3))
        np.add.at(out, inv.ravel(), v)              # (at most two terms a block: the same sum either way)
        return key // len(self.loc), (key % len(self.loc)).astype(np.int32), out


def _first_occurrences(h, meta, full_keys):
    """(first, inverse) of the distinct requests: first occurrence (in the order given) of each
    (hash, lo, hi), and for each request the index of its distinct one. Hash collisions (equal
    hash, different key) are rare: if the keys of a group differ, the full keys decide
    (``full_keys()``: the (m, 29) rows key + lo + hi)."""
    m = len(h)
    if m == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    order = np.lexsort((np.arange(m), meta[:, 1], meta[:, 0], h))
    hs, lo, hi = h[order], meta[order, 0], meta[order, 1]
    new = np.r_[True, (hs[1:] != hs[:-1]) | (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1])]
    group = np.cumsum(new) - 1
    first = order[new]
    inv = np.empty(m, np.int64)
    inv[order] = group
    keys = full_keys()
    if np.any(keys != keys[first[inv]]):
        _, first, inv = np.unique(keys, axis=0, return_index=True, return_inverse=True)
        inv = inv.ravel()
    return first, inv


def _mix64(h):
    """A 64-bit finaliser (splitmix64) of the element-cache hashes: their low bits alone are not
    uniform, and the owner rank of a geometry is the hash modulo the ranks."""
    x = h.astype(np.uint64)
    with np.errstate(over="ignore"):
        x ^= x >> np.uint64(30)
        x *= np.uint64(0xBF58476D1CE4E5B9)
        x ^= x >> np.uint64(27)
        x *= np.uint64(0x94D049BB133111EB)
        x ^= x >> np.uint64(31)
    return x


def _send_segments(mpi, jobs, recv):
    """Collective all-to-all of segments of doubles, in place at both ends: to rank r the segments
    P[ps:ps + pl] then U[us:us + ul] of ``jobs[r]`` = (P, ps, pl, U, us, ul), one after the other;
    from rank r, in the same order, into the segments ``recv[r]`` = (lengths, absolute addresses).
    MPI datatypes at the segments' addresses: no packed copy of the element cache at either end (a
    send buffer and a receive buffer each as large as the cache itself, in fresh memory)."""
    from mpi4py import MPI
    p = mpi.Get_size()
    made = []

    def segments(lens, addr):
        """(datatype, count) of the doubles at absolute addresses ``addr``, ``lens`` each."""
        lens, addr = np.asarray(lens, np.int64), np.asarray(addr, np.int64)
        keep = lens > 0
        if not keep.any():
            return MPI.DOUBLE, 0
        made.append(MPI.DOUBLE.Create_hindexed(lens[keep].tolist(), addr[keep].tolist()).Commit())
        return made[-1], 1
    send = []
    for P, ps, pl, U, us, ul in jobs:
        aP = MPI.Get_address(P) if P.size else 0            # (an empty pool: every length 0)
        aU = MPI.Get_address(U) if U.size else 0
        send.append(segments(np.r_[pl, ul], np.r_[aP + 8 * np.asarray(ps, np.int64), aU + 8 * np.asarray(us, np.int64)]))
    rv = [segments(lens, addr) for lens, addr in recv]
    stypes, scounts = [t for t, _ in send], [c for _, c in send]
    rtypes, rcounts = [t for t, _ in rv], [c for _, c in rv]
    try:
        mpi.Alltoallw([MPI.BOTTOM, (scounts, [0] * p), stypes], [MPI.BOTTOM, (rcounts, [0] * p), rtypes])
    finally:
        for t in made:
            t.Free()


class LagSet:
    """The assembled H_l, G_l (l = 1..L) of one rank as triplets, then Mats."""

    def __init__(self, comm, mesh, mat, dt, L, regions, planes, opts):
        from .bsr import FULL
        from .assemble import KERNELS, PLANE, surface_kind, patterns
        self.comm = comm
        self.mesh, self.mat, self.dt, self.L = mesh, mat, dt, L
        self.regions, self.planes, self.opts = regions, planes, opts
        VX, VN, VS, VT = symmetry.virtual_elements(mesh.cell_coords(), mesh.cells, regions.tcols, planes)
        self.VX, self.VN, self.VS, self.VT = VX, VN, VS, VT
        # the kernel table (assemble.KERNELS): the surface's kind (every collocation point and element in
        # z = 0, in one plane z = z0, or not) -> the block patterns (bsr.PATTERNS: H 4 and G 5 entries a
        # block in one plane, else the general 3x3; opts "block_pattern": "full" forces it: the check of
        # both paths) and in the plane z = 0 the regular pairs by quadrature.integrate_plane (the geometry
        # of each element's Gauss points computed once, the pattern's entries only: the same bits)
        self.kind = surface_kind(mesh.nodes, VX)
        self.mH, self.mG = patterns(self.kind, opts.get("block_pattern", "auto"))
        self.flat = self.mH != FULL
        # a surface that is not one plane (an excavation) with the general pattern chosen automatically: H's
        # blocks whose pairs all lie in one horizontal plane keep the flat pattern (``SplitBuckets``)
        self.split = self.kind == "general" and opts.get("block_pattern", "auto") == "auto"
        self.in_plane = KERNELS[(self.kind, (self.mH, self.mG))][0] == PLANE
        self._plane = None
        self.Vc, self.VR, self.Vh = bounding_spheres(VX)
        from .partition import node_ranges, lag_weights, equal_ranges
        # the nodes (rows) of each rank: contiguous ranges of equal estimated work (-ssi_partition);
        # opts "lag_weights": uses of the matrices by lag (partition.lag_weights), "work_lags": the
        # exact lags (default: a stabilised run of L steps storing every lag)
        Lx = int(opts.get("work_lags") or L)
        lw = opts.get("lag_weights")
        if opts.get("partition") == "equal" and not opts.get("weigh", True):
            # (no estimate of the lags' work to report: the toeplitz store's history is split by frequency)
            self.ranges, self.balance = equal_ranges(mesh.n_nodes, comm.getSize()), None
        else:
            self.ranges, self.balance = node_ranges(comm, opts.get("partition", "balanced"), mesh.nodes, self.Vc,
                                                    self.VR, mat, dt, len(self.Vc) // mesh.n_cells,
                                                    np.asarray(lw, float) if lw is not None
                                                    else lag_weights(Lx, L, True), Lx, regions.n_t)
        self.node_range = self.ranges[comm.getRank()]
        self.rows = np.arange(*self.node_range, dtype=np.int64)
        from .freeterm import free_terms
        self.cfree = free_terms(VX, VN, mesh.n_nodes, mat.nu, nodes=self.rows)
        self.n_nonsmooth = self.comm.tompi4py().allreduce(
            int(np.sum(np.abs(self.cfree[self.rows] - 0.5 * np.eye(3)).max(axis=(1, 2)) > 1e-14)))

    def estimate_memory(self, lags, storage="auto", fill=0.95, extra_lags=(), sample=0, single_from=0,
                        load=True):
        """Collective: estimated bytes of the stored Mats and the assembly peak (all ranks).

        ``lags``: number of exact lags; ``extra_lags``: lag indices standing in
        for interpolating matrices. Each lag is stored dense (N^2 x 8 m B) or
        block-sparse (8 m + 4 B per block; m the entries of its block pattern, bem/bsr.py) by the same
        rule as the build (``lag_bytes``); the assembled blocks (``Buckets``: the same bytes, 4 m + 4
        single, in arrays sized from this count with 15 %
        headroom that is never touched, so not resident) become the block-sparse Mats
        as they are, or are freed lag by lag as dense Mats are built, so the
        peak is max_k [Mats of lags <= k + blocks of lags > k] (``peak_bytes``, also the
        interpolating matrices' assemblies after them), times 1.1. Per rank on top:
        the element cache (``cache_estimate``: 81 doubles per distinct pair geometry and lag
        in each of two pools, which grow by doubling: twice that; each pool capped at
        CACHE_MAX) and one row's work while the blocks are assembled and the process as it stands now (its resident size, measured after
        loading the kernels unless ``load`` is False). ``sample`` > 0: the blocks counted on every
        k-th local row only (at most ``sample`` rows per rank) and scaled up, a fast estimate.
        ``single_from`` > 0: lags from it on (exact or interpolating) kept in single precision
        (``lag_bytes``)."""
        nimg = len(self.Vc) // self.mesh.n_cells
        L = max([lags] + list(extra_lags))
        rows = self.rows
        if not sample and load:
            load_kernels()          # the process measured with the compiled kernels it will hold
        if sample and len(rows) > sample:
            rows = rows[::int(np.ceil(len(rows) / sample))]
        nb = estimate_blocks(self.mesh.nodes, rows, self.Vc, self.VR, L, self.mat, self.dt, nimg)
        nb = nb * (len(self.rows) / max(len(rows), 1))
        mpi = self.comm.tompi4py()
        nbf = None
        if self.split:          # the blocks H keeps in the flat pattern (``SplitBuckets``)
            nbf = estimate_blocks(self.mesh.nodes, rows, self.Vc, self.VR, L, self.mat, self.dt, nimg,
                                  plane_z=plane_heights(self.VX, nimg)) * (len(self.rows) / max(len(rows), 1))
            nbf = mpi.allreduce(nbf)
            nbf = np.r_[nbf[:lags], [nbf[l - 1] for l in extra_lags]] if len(extra_lags) else nbf[:lags]
        local_blocks = float(nb[:lags].sum())
        local_interp = max([float(nb[l - 1]) for l in extra_lags] + [0.0])
        nb = mpi.allreduce(nb)
        use = np.r_[nb[:lags], [nb[l - 1] for l in extra_lags]] if len(extra_lags) else nb[:lags]
        N = self.mesh.n_nodes
        f = use / float(N * N)
        single = single_lags(np.r_[np.arange(1, lags + 1), list(extra_lags)], single_from)
        dense = ((f > fill) if storage == "auto" else np.full(len(use), storage == "dense")) & ~single
        mats, trip, g = lag_bytes(use, dense, single, N, N, self.regions.n_t, self.mH, self.mG, nbf)
        cache = None if sample else self.cache_estimate(lags, extra_lags)    # (sample: the bound per block)
        asm, rss = (mpi.allreduce(v) for v in transient_bytes(local_blocks, N, L, len(self.rows), cache, parts=True))
        asm_i = mpi.allreduce(transient_bytes(local_interp, N, 1, len(self.rows), parts=True)[0]) if len(extra_lags) else 0.0
        peak = peak_bytes(mats, trip, g, asm, rss, n_exact=lags, asm_interp=asm_i)
        return float(mats.sum() + g.sum()), float(peak), int(dense.sum())

    def restricted(self, keep):
        """A LagSet of the same rows over the virtual elements ``keep`` (a mask), for an assembly
        of their contributions only (``build._traction_g``: the elements with traction columns)."""
        import copy
        o = copy.copy(self)
        for a in ("VX", "VN", "VS", "VT", "Vc", "VR", "Vh"):
            setattr(o, a, np.ascontiguousarray(getattr(self, a)[keep]))
        o._plane = None
        o.n_images = 1              # (the capacity estimate: each kept element apart, an upper bound)
        o.__dict__.pop("_cache_est", None)
        return o

    CACHE_MAX = CACHE_MAX        # bytes per cache pool (P and U): 1 GiB per rank at most

    def pattern(self):
        """The kernels' block patterns (bem/bsr.py PATTERNS): (H's p, q, G's p, q, H's keep mask, G's)."""
        from .bsr import positions
        (hp, hq), (gp, gq) = positions(self.mH), positions(self.mG)
        hkeep, gkeep = np.zeros((3, 3), np.bool_), np.zeros((3, 3), np.bool_)
        hkeep[hp, hq] = True
        gkeep[gp, gq] = True
        return hp, hq, gp, gq, hkeep, gkeep

    def cache_estimate(self, lags, extra_lags=()):
        """Bytes of this rank's element cache in the assembly of the exact lags 1..``lags`` (both
        pools, 81 doubles per pair geometry and lag each, each pool capped at CACHE_MAX), counted
        from the distinct pair geometries of its rows as ``petsc-ssi estimate`` counts them
        (``estimate.pair_table``); 0 without the cache (-ssi_cache 0)."""
        if not self.opts.get("cache", True):
            return 0.0
        key = (int(lags), tuple(extra_lags))
        if getattr(self, "_cache_est", (None,))[0] != key:
            table = pair_table(self, self, max([lags] + list(extra_lags)), rows=self.rows)
            r0, r1 = self.node_range
            sP, sU = 9 * self.mH, 9 * self.mG
            slots = cache_counts(table, r0, r1, self.CACHE_MAX / 8, lags, extra_lags, stride=max(sP, sU))[1]
            self._cache_est = (key, 8.0 * (sP + sU) * slots)
        return self._cache_est[1]

    def kernels(self, quad):
        """The kernels' pack of the assembly (``assemble.kernels``: the kernel table's choice for this
        surface and the block patterns as they stand, the plane geometry of ``quad``)."""
        from .assemble import kernels
        return kernels(self.kind, self.pattern(), self.plane(quad.gq, quad.gw))

    def kernel_packs(self, lag_lo, lag_hi, toff):
        """(mesh, lags, phys, quad): the assembly kernels' packs of lags lag_lo..lag_hi at kernel times
        l dt + toff (``assemble.assemble_rows``)."""
        from .assemble import SING_TOL
        mesh = (self.mesh.nodes, self.VX, self.VN, self.VS, self.VT, self.Vc, self.VR, self.Vh)
        phys = packs.wave(self.dt, self.mat.cp, self.mat.cs, self.mat.rho, self.mat.nu, toff)
        return mesh, (int(lag_lo), int(lag_hi)), phys, packs.quad_from(self.opts, float(self.Vh.min()), SING_TOL)

    def plane(self, gq, gw):
        """The plane geometry of the assembly kernels (``assemble.plane``), made once: the Gauss
        points' geometry of every virtual element at -ssi_subdivisions (nv ns^2 ng^2 x 4 doubles: 2 KB
        an element at the defaults) when the surface is the plane z = 0."""
        o = self.opts
        key = (len(gq), int(o["subdivisions"]), int(o["max_subdivisions"]))
        if self._plane is None or self._plane[0] != key:
            from .assemble import plane
            self._plane = (key, plane(self.in_plane, self.VX, key[1], gq, gw, key[2]))
        return self._plane[1]

    def row_work_bytes(self, lag_hi):
        return row_work_bytes(self.mesh.n_nodes, lag_hi)

    def chunk_rows(self, lag_hi):
        """Rows per numba call (the progress monitor's steps: the kernel writes each row's blocks where
        they are kept, so its memory does not grow with it): the rule of a chunk of about 256 MB of
        triplets the kernel once held, at least one row."""
        return chunk_rows(self.mesh.n_nodes, lag_hi, len(self.rows))

    def candidates(self, rows, pk):
        """(ptr, elements, 0) of ``rows``' candidate elements for the packs ``pk`` (``windows.candidates``: the
        elements within the lags' P-wave reach, where it is a small share of the surface), or empty arrays: every
        element (the assembly kernels' ``cand``)."""
        from .packs import CP, DT, TOFF
        phys = pk[2]
        got = candidates(self.mesh.nodes[rows], self.Vc, self.VR,
                         float(phys[CP] * (phys[DT] * pk[1][1] + phys[TOFF])))
        return (got if got is not None else (np.zeros(0, np.int64), np.zeros(0, np.int32))) + (0,)

    def _share_cache(self, cache, pk, kern, qinv, dropped, cand):
        """Collective: fill this rank's element cache (``cache``: cidx, ckeys, cmeta, cpP, cpU, as from
        assemble.new_cache) for the assembly of ``pk`` (mesh, lags, phys, quad: ``kernel_packs``) with the
        kernels of ``kern`` (``kernels``) with every distinct pair geometry its rows meet,
        each integrated once over all ranks. A geometry's owner is its hash modulo the ranks; requests
        go to the owners (all-to-all of keys), the owner integrates the representative of the lowest
        requesting rank (the pair a single rank would meet first, so -n p reproduces -n 1) and sends
        the blocks back (all-to-all-v of doubles); ``cand``: the rows' candidate elements (``candidates``,
        as the assembly's). Returns the cache arrays and the owned evaluations."""
        from .assemble import cache_index, enumerate_pairs, index_len, integrate_batch
        cidx, ckeys, cmeta, cpP, cpU = cache
        if index_len(cidx):             # (the same on every rank: assemble() passes a new cache)
            raise RuntimeError("_share_cache fills an empty element cache only")
        mesh, lags, phys, quad = pk
        mpi = self.comm.tompi4py()
        p = mpi.Get_size()
        sP, sU = 9 * len(kern[1][0]), 9 * len(kern[1][2])       # doubles a lag slot (assemble._compact)
        with collective(self.comm, "listing the element-cache geometries"):     # e.g. MemoryError on one rank
            keys, hs, meta, pts = enumerate_pairs(self.rows, mesh, lags, phys, quad, qinv, self.CACHE_MAX,
                                                  max(sP, sU), cand)
        owner = np.mod(_mix64(hs), p)
        mine = [np.nonzero(owner == r)[0] for r in range(p)]
        got = mpi.alltoall([(keys[i], hs[i], meta[i], pts[i]) for i in mine])
        # owner: the distinct requests (key, lo, hi), first occurrence in rank order; want_u if any wants it
        allh = np.concatenate([g[1] for g in got])
        allm = np.concatenate([g[2] for g in got])
        first, inv = _first_occurrences(allh, allm, lambda: np.concatenate([np.c_[g[0], g[2][:, :2]] for g in got]))
        umeta = allm[first].copy()
        umeta[inv[allm[:, 4] == 1], 4] = 1                    # (flags 0/1: np.maximum.at, without its slowness)
        allh = None
        with collective(self.comm, "integrating the shared element-cache geometries"):
            off, P, uoff, U, nev = integrate_batch(umeta, np.concatenate([g[3] for g in got])[first], self.VX,
                                                   lags[1], phys, quad, kern, dropped)
        # replies: per requester, its records in its order: P blocks, then U blocks of those wanting U
        seg = np.cumsum([0] + [len(g[2]) for g in got])
        jobs = []
        for r in range(p):
            u = inv[seg[r]:seg[r + 1]]
            w = u[got[r][2][:, 4] == 1]
            jobs.append((off[u], off[u + 1] - off[u], uoff[w], uoff[w + 1] - uoff[w]))
        got = None
        # this rank's records straight into fresh pools, in record order: record i's P blocks at lag slot
        # pslot[i] of the P pool, its U blocks (if it wants them) at uslot[i] of the U pool
        nl = meta[:, 1] - meta[:, 0] + 1
        wu = meta[:, 4] == 1
        pslot = np.cumsum(nl) - nl
        uslot = np.where(wu, np.cumsum(np.where(wu, nl, 0)) - np.where(wu, nl, 0), -1)
        cpP = np.empty(max(int(nl.sum()), 1) * sP)           # (at least a slot: an address to give MPI)
        cpU = np.empty(max(int(nl[wu].sum()), 1) * sU)
        from mpi4py import MPI
        aP, aU = MPI.Get_address(cpP), MPI.Get_address(cpU)
        recv = []
        for r in range(p):
            i = mine[r]
            w = i[wu[i]]
            recv.append((np.r_[nl[i] * sP, nl[w] * sU], np.r_[aP + 8 * sP * pslot[i], aU + 8 * sU * uslot[w]]))
        _send_segments(mpi, [(P, ps, pl, U, us, ul) for ps, pl, us, ul in jobs], recv)
        P = U = jobs = recv = None
        ckeys, cmeta = cache_index(cidx, ckeys, cmeta, keys, hs, meta, pslot, uslot)
        return ckeys, cmeta, cpP, cpU, int(nev)

    def assemble(self, monitor=False, chunk=None, lag_lo=1, lag_hi=None, toff=0.0, what="BEM assembly",
                 single_from=0, quiet=False, keep_h=True):
        """Lags lag_lo..lag_hi (default 1..L) at kernel times l dt + toff,
        each rank its rows; sets and returns (H, G) Buckets (lags >= ``single_from`` > 0 kept in
        float32: -ssi_lag_single_from). ``quiet``: no -log_view event (``load_kernels``); ``keep_h`` False:
        G only, H's blocks not written (``build._traction_g``)."""
        from .bsr import H4
        from .assemble import assemble_rows, index_len, new_cache, new_work
        o = self.opts
        lag_hi = self.L if lag_hi is None else lag_hi
        rows = self.rows
        chunk = chunk or self.chunk_rows(lag_hi - lag_lo + 1)
        prog = Progress(what, max(len(rows), 1), enabled=monitor, unit="row", comm=self.comm)
        nimg = getattr(self, "n_images", None) or len(self.Vc) // self.mesh.n_cells
        est = estimate_blocks(self.mesh.nodes, rows, self.Vc, self.VR, lag_hi, self.mat, self.dt, nimg)
        est[:lag_lo - 1] = 0
        cap = 1.15 * est if keep_h else np.zeros_like(est)
        mH, mG = self.mH, self.mG
        est_flat = None
        if self.split and keep_h:       # (the flat part's expected blocks: where its last page is; room as H's)
            est_flat = estimate_blocks(self.mesh.nodes, rows, self.Vc, self.VR, lag_hi, self.mat, self.dt, nimg,
                                       plane_z=plane_heights(self.VX, nimg))
            est_flat[:lag_lo - 1] = 0
        small = bool(self.opts.get("small_pages", False))      # -ssi_huge_pages (petsc.lag_small_pages)
        H = Buckets(lag_hi, rows, self.mesh.n_nodes, cap, single_from=single_from, m=mH,
                    free=self.cfree[rows] if lag_lo == 1 else None,
                    expected=est if est_flat is None else est - est_flat, small=small)
        # G: a block for every traction column a row's wave window reaches; room for all of them (never
        # touched beyond what is written: not resident) unless that is more than the node's memory
        gcap = np.full(lag_hi, len(rows) * self.regions.n_t, np.int64)
        gcap[:lag_lo - 1] = 0
        from ..sysmem import machine_memory, release_freed
        if gcap.sum() * (8.0 * mG + 4) > 0.5 * machine_memory():
            gcap[:] = 0
        G = Buckets(lag_hi, rows, self.mesh.n_nodes, gcap, single_from=single_from, m=mG, small=small)
        dropped = np.zeros(2)
        nev = 0
        ev = _NoEvent() if quiet else event("SSI_BEM_Assembly")
        ev.begin()
        cidx, ckeys, cmeta, cpP, cpU = new_cache()
        qinv = 1.0 / (1e-9 * float(self.Vh.min()))
        hits = 0
        pk = self.kernel_packs(lag_lo, lag_hi, toff)
        kern = self.kernels(pk[3])
        cand = self.candidates(rows, pk)
        if o.get("cache", True) and o.get("cache_share", True) and self.comm.getSize() > 1:
            with event("SSI_BEM_Integrate"):
                ckeys, cmeta, cpP, cpU, nev = self._share_cache((cidx, ckeys, cmeta, cpP, cpU), pk, kern, qinv,
                                                                dropped, cand)
            release_freed()         # the integrals' temporaries and messages: not resident through the assembly
        work = new_work(self.mesh.n_nodes, self.regions.n_t, len(self.VX), mH=mH, mG=mG)
        hout = H.out() if keep_h else H.out()[:5] + (-1,)
        if est_flat is not None:        # the coplanar blocks' part (``SplitBuckets``)
            H = SplitBuckets(H, Buckets(lag_hi, rows, self.mesh.n_nodes, cap, single_from=single_from, m=H4,
                                        expected=est_flat, small=small))
        out = (hout, G.out(), H.loc, H.flat.out() if isinstance(H, SplitBuckets) else hout[:5] + (-1,))
        for s in range(0, len(rows), chunk):
            cache = (bool(o.get("cache", True)), cidx, ckeys, cmeta, cpP, cpU, qinv, self.CACHE_MAX)
            work, n_ev, n_hit, cache = assemble_rows(rows[s:s + chunk], *pk, kern, cache, work, dropped, out,
                                                     cand[:2] + (s,))
            ckeys, cmeta, cpP, cpU = cache[2:6]
            nev += n_ev
            hits += n_hit
            prog.update(min(s + chunk, len(rows)))
        work = None
        release_freed()
        ev.end()
        from mpi4py import MPI
        lost = self.comm.tompi4py().allreduce(float(dropped.max()), op=MPI.MAX)
        if lost != 0.0:        # (cannot happen on a plane: r . n = 0 makes those entries exact zeros)
            raise SSIError(f"BEM assembly: a flat-surface block entry outside its pattern is {lost:.3g}, not 0 "
                           "(bem/bsr.py PATTERNS); report this with the mesh")
        self.cache_entries = int(index_len(cidx))
        self.cache_hits = self.comm.tompi4py().allreduce(hits)
        self.cache_bytes = self.comm.tompi4py().allreduce(cpP.nbytes + cpU.nbytes)
        self.H, self.G = H, G
        self.kernel_evaluations = self.comm.tompi4py().allreduce(nev)
        return self.H, self.G
