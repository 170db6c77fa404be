r"""Lag matrices of a uniform flat grid as block-Toeplitz convolutions, the history sum in Fourier space
(issue 41; ``-ssi_lag_store toeplitz``).

On a surface whose elements (and their symmetry images) are equal axis-aligned squares or rectangles
hx x hy on a lattice of centres c = o + (i hx, j hy), with their nodes at c + delta_a (the nine
positions {-h/2, 0, h/2}^2, ``SLOTS``), every entry of a lag matrix is a sum over elements e and
their local nodes a of one element's integral that depends only on the offset x_i - c_e and on a:

    (H_l u)(x) = sum_a sum_e K_{l,a}(x - c_e) v_a(e),    v_a(e) = S_e u(node of e at c_e + delta_a)

(S_e the image's sign, ``symmetry``). A collocation point is a node, x = c + ((2k + t_x) hx/2,
(2k' + t_y) hy/2) with parity class t = (t_x, t_y) (corner, two edge and centre nodes), so per class
the sum over e is a discrete 2-D convolution on the lattice: nine convolutions (one per a) for each
of four classes, each a 3x3 block with the flat surface's H pattern (4 entries, ``bsr.H4``). A lag is
stored as the 2-D real FFTs of its kernels on a zero-padded grid Mx x My >= 2 nx x 2 ny (so the
circular convolution is the linear one on the lattice), O(N) numbers instead of O(N^2). The kernels
are the same integrals the dense path computes (``assemble.integrate_records`` on one element of the
grid at every offset; by the element's mirror symmetry one integral at |o| serves the four offsets
(+-o_x, +-o_y), ``_scatter_kernels``), so the answer is the dense path's to round-off.

The history sum of the marching scheme (``march``) over the exact lags 2..Lx and the interpolating
matrices is one stationary convolution in time, sum_d K'_d u^{n-d}, whose kernel K'_d (d = 1..D) is the
linear combination of lag kernels the scheme's terms give (``Marcher._step_terms``: plain, stabilised,
multi-linear or Chebyshev interpolation beyond T_L alike). Each state u^m is transformed once (27
real FFTs: nine node slots, three components) and kept while a kernel reads it; per step the
products sum over d in Fourier space and four classes x three components go back by inverse FFTs.
Kernels and kept transforms are stored in frequency lanes (``lanes``: 8 frequencies side by side, real
and imaginary parts apart) so that the products compile to a register-blocked vector micro-kernel without
copies. Where the kernels' offsets are point-symmetric (a whole grid's H side, ``point_sign``), a slot's
spectrum and its point mirror's are conjugate up to a known phase, K_{8-a}(f) = s exp(-2 i psi_t(f))
conj(K_a(f)): the pairs' sum and difference, rotated by exp(i psi_t), are real, so the kernels are stored
real (half the bytes, half the multiply-adds) and the states as the pairs' sums and differences
(``ToeplitzHistory._source``, ``_pairs``, ``_rotation``).

Parallel: the 2-D FFTs go over the ranks through mpi4py-fft (``pfft``: a slab decomposition, FFTW
underneath): each rank holds the grid's rows x0..x1 in physical space and, of every kernel and kept state, the
frequencies of its columns of the half spectrum (all k_x), stored k_y-major (memory divided by the ranks). The
kernels' integrals are split by offset; each chunk's planes are summed onto the ranks of their rows (an MPI
Reduce a row block) and transformed over the ranks. Per step a PETSc scatter brings each rank the nodes its
grid rows read, mpi4py-fft transforms the 27 planes (its own all-to-all between the two passes), the products
run on the rank's frequencies, and the 12 summed planes go back the same way, a PETSc scatter taking each
node's value from the rank whose rows hold it: the Fourier-space history gathers no whole state or spectrum
(lags 1-2, Mats, move each rank's rows' columns and a halo: ``bsr.reader``). A frequency's
products are summed in the same order on any number of ranks, so ``-n 2`` equals ``-n 1`` to round-off (the
tests: 1e-12 relative; tests/bem/test_pfft.py for the transforms alone).

G (traction columns): lags 1-2 are Mats as H's; its lags from 3 on are kernels too, on the traction elements'
window (``traction_grid``, side "p"). The step matrix (lags 1 and 2) is assembled and factorised as before.
"""
import math
import time

import numpy as np
from numba import njit

from ..petsc import SSIError, printf, init
from ..monitor import event
from .assemble import _pair_window
from .pfft import slab_counts
from .lanes import (FW, n_groups, padded, put_spectra, history_lanes, interp_lanes, interp_flops,
                    scatter_slots, put_state_grid, unpack_grid, CHUNK_GROUPS)

# the nine node positions of an element relative to its centre, in half element sizes
SLOTS = [(dx, dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1)]
CLASSES = ((0, 0), (0, 1), (1, 0), (1, 1))      # node parity (t_x, t_y): 0 on a centre line, 1 on an edge


class Lattice:
    """The uniform grid of a surface: lattice of element centres, node slots, parity classes of the
    nodes (``detect``)."""

    def __init__(self, o, h, nx, ny, cell, perm, node_fine, code0):
        self.o, self.h, self.nx, self.ny = o, h, nx, ny
        self.cell = cell                # (nv,) flat lattice index ix * ny + iy of each virtual element
        self.perm = perm                # (nv, 9): local node of element v at slot a (SLOTS)
        self.node_fine = node_fine      # (N, 2): a node's position in half element sizes from o
        self.code0 = code0              # (9,): the slot of each local node of element 0 (the kernels')
        self.in_lo, self.in_n = (0, 0), (nx, ny)    # the lattice box of the inputs (``window``)
        self._fft_grid()

    def _fft_grid(self):
        """The FFT grid: a circular convolution of size M gives the linear one on the outputs of lattice
        indices r0..r1 (the nodes' span) from inputs lo..lo+n-1 (placed at 0..n-1) when M >= r1 - r0 + n
        (their offsets then differ modulo M): 2 n for a whole grid, less for a symmetric model's rows in
        one quarter or for inputs on a patch (the G side: the traction elements only)."""
        from scipy.fft import next_fast_len
        node_fine = self.node_fine
        span = [self.nx + self.in_n[0], self.ny + self.in_n[1]]
        if len(node_fine):
            for ax in (0, 1):
                i = (node_fine[:, ax] - (node_fine[:, ax] & 1)) // 2
                span[ax] = int(i.max() - i.min() + self.in_n[ax])
        self.Mx = next_fast_len(span[0], real=True)
        # (at least 3 columns: mpi4py-fft's slab transform fails on a half spectrum of My // 2 + 1 = 2 columns with
        # My = 2, tests/bem/test_pfft.py; a larger M only pads more)
        self.My = next_fast_len(max(span[1], 3), real=True)
        self.F = self.Mx * (self.My // 2 + 1)

    def window(self, sel):
        """A copy of this grid whose inputs are the virtual elements ``sel`` (bool) only: their lattice box
        is the input range and the FFT grid is sized for it (the G side, whose inputs are the elements
        carrying traction columns)."""
        ix, iy = self.cell[sel] // self.ny, self.cell[sel] % self.ny
        lo = (int(ix.min()), int(iy.min()))
        return self.window_box(lo, (int(ix.max()) - lo[0] + 1, int(iy.max()) - lo[1] + 1))

    def window_box(self, lo, n):
        """A copy of this grid whose inputs are the lattice box lo .. lo + n - 1 (its point symmetry unknown)."""
        import copy
        w = copy.copy(self)
        w.in_lo, w.in_n = (int(lo[0]), int(lo[1])), (int(n[0]), int(n[1]))
        w.point_symmetric = None
        w._fft_grid()
        return w

    def describe(self):
        return (f"{self.nx} x {self.ny} lattice of {self.h[0]:g} x {self.h[1]:g} m elements (FFT grid "
                f"{self.Mx} x {self.My})")


def detect(VX, nodes, what="-ssi_lag_store toeplitz", n_cells=None):
    """The Lattice of virtual elements VX (nv, 9, 3) and nodes (N, 3), or SSIError naming the first
    element that is not on it (a surface not in the plane z = 0, elements of another size or shape,
    off the lattice, overlapping or turned over). ``n_cells``: the mesh's elements, VX's first rows (the
    rest their symmetry images: the message says so)."""
    VX = np.asarray(VX, float)
    nodes = np.asarray(nodes, float)
    if VX.shape[0] == 0:
        raise SSIError(f"{what}: the surface has no elements")
    X0 = VX[0]
    h = np.array([np.ptp(X0[:, 0]), np.ptp(X0[:, 1])])
    if h.min() <= 0:
        raise SSIError(f"{what}: element 0 is not a rectangle in the plane z = 0")
    tol = 1e-9 * float(h.max())
    if np.abs(VX[..., 2]).max() > tol or (nodes.size and np.abs(nodes[:, 2]).max() > tol):
        v = int(np.argmax(np.abs(VX[..., 2]).max(axis=1)))
        raise SSIError(f"{what}: the surface is not the plane z = 0 (element {v} at z = "
                       f"{VX[v, :, 2].min():.6g} m); a grid of FFT lags needs a flat surface")
    c = 0.25 * (VX[:, 0] + VX[:, 1] + VX[:, 2] + VX[:, 3])           # centre of the corners
    rel = (VX[..., :2] - c[:, None, :2]) / (0.5 * h)
    fine = np.rint(rel)
    bad = np.abs(rel - fine).max(axis=(1, 2)) > 1e-9 * 2
    bad |= np.abs(fine).max(axis=(1, 2)) > 1
    code = ((fine[..., 0] + 1) * 3 + (fine[..., 1] + 1)).astype(np.int64)
    bad |= np.any(np.sort(code, axis=1) != np.arange(9)[None, :], axis=1)
    # orientation: the signed area of the corners (images keep the outward normal: symmetry.FLIP)
    P = VX[:, :4, :2]
    area = 0.5 * np.sum(P[:, :, 0] * np.roll(P[:, :, 1], -1, axis=1) - np.roll(P[:, :, 0], -1, axis=1) * P[:, :, 1],
                        axis=1)
    bad |= np.sign(area) != np.sign(area[0])
    if bad[0]:                  # (the others are measured against element 0: it must be one itself)
        raise SSIError(f"{what}: element 0 (centre {c[0, 0]:.6g}, {c[0, 1]:.6g} m) is not a nine-node rectangle with "
                       "its sides along x and y (straight sides, mid-side nodes): a grid of FFT lags needs cells "
                       "along the axes (turn the mesh so they are), or use -ssi_lag_store dense")
    if np.any(bad):
        v = int(np.argmax(bad))
        raise SSIError(f"{what}: element {v} (centre {c[v, 0]:.6g}, {c[v, 1]:.6g} m) is not a "
                       f"{h[0]:g} x {h[1]:g} m nine-node rectangle like element 0 (same size, straight sides, "
                       "mid-side nodes, the same orientation); use -ssi_lag_store dense")
    o = c[:, :2].min(axis=0)
    g = (c[:, :2] - o) / h
    gi = np.rint(g)
    off = np.abs(g - gi).max(axis=1) > 1e-9
    if np.any(off):
        v = int(np.argmax(off))
        k = int(np.argmin(np.where(np.isclose(c[:, 0], o[0]), c[:, 1], np.inf)))    # (an element at the origin)
        if n_cells is not None and max(v, k) >= n_cells:
            where = (" (with -ssi_symmetry the elements' mirror images count, element n + i the image of element "
                     f"i, {n_cells} elements: the mesh and its images must lie on one grid; does the mesh reach the "
                     "planes?)")
        else:
            where = ""
        raise SSIError(f"{what}: element {v} (centre {c[v, 0]:.6g}, {c[v, 1]:.6g} m) is off the grid of "
                       f"{h[0]:g} x {h[1]:g} m cells through element {k}'s centre ({c[k, 0]:.6g}, {c[k, 1]:.6g} m)"
                       f"{where}; use -ssi_lag_store dense")
    gi = gi.astype(np.int64)
    nx, ny = int(gi[:, 0].max()) + 1, int(gi[:, 1].max()) + 1
    cell = gi[:, 0] * ny + gi[:, 1]
    u, first, cnt = np.unique(cell, return_index=True, return_counts=True)
    if np.any(cnt > 1):
        dup = u[cnt > 1][0]
        v = int(np.nonzero(cell == dup)[0][1])
        raise SSIError(f"{what}: element {v} (centre {c[v, 0]:.6g}, {c[v, 1]:.6g} m) overlaps element "
                       f"{int(np.nonzero(cell == dup)[0][0])}")
    perm = np.argsort(code, axis=1)          # slot a (code a) -> local node
    nf = (nodes[:, :2] - o) / (0.5 * h) if nodes.size else np.zeros((0, 2))
    nfi = np.rint(nf)
    if nodes.size and np.abs(nf - nfi).max() > 1e-9 * 2:
        i = int(np.argmax(np.abs(nf - nfi).max(axis=1)))
        raise SSIError(f"{what}: node {i} is off the grid's half-element positions")
    return Lattice(o, h, nx, ny, cell, perm, nfi.astype(np.int64), code[0].copy())


# cost model (``estimate``). The time rates r_products (the history's complex products per rank: the
# block products' flops over this rate), the per-step work of every rank that is not split over the ranks
# (t_step_dof a DOF, t_step_grid an FFT grid point, t_step_elem a virtual element: the state's gather, the
# 27 + 12 transforms' inputs element by element, images included), the kernels' build (t_pair_lag: seconds per H
# kernel offset and lag of its integrals, its planes' scatter, transforms and exchange, for 9 slots, 5 on a real
# side; g_pair_factor: a G offset's cost in H offsets; t_kernel_byte: seconds per byte of a side's kernels a rank
# writes, ``lanes.put_spectra``, which on this VM is mostly the first write of fresh memory, the host's pages)
# are fitted by `python jobscripts/toeplitz_fit.py` (t_kernel_byte to the logs' 'weights' seconds, t_pair_lag and
# g_pair_factor to the rest of each side's build, the log's parts of 'kernels T s: integrals ...'; the history's
# terms to SSI_BEM_History less the kept states' transforms' first write, which a run pays once, at t_kernel_byte a
# byte; r_products and the per-step terms are nearly collinear on runs of a few hundred steps, and a run of 1000
# steps in the logs separates them) to 14 logs: `PARTS="paper grid site" SITE_SIZES="40 60 80" SITE_EXACT=""
# OUT=<dir> bash jobscripts/quiet.sh bash jobscripts/toeplitz_bench.sh` (grids of 24-64 m, the paper's quarter and
# whole models, the sites of 40-80 m with multi-linear far lags and single-precision transforms; the toeplitz rows),
# `OUT=<dir> RUNS="uniform-36-smooth uniform-72-area-exact uniform-72-smooth uniform-108-smooth" bash
# jobscripts/quiet.sh bash jobscripts/building_uniform.sh` (the building on uniform grids of 36-108 m, every lag
# exact), 2026-12-03 14:10-14:18, and runs/seismic/site_oblique.sh's run (the 28.8 m building on a 72 m grid, 1000
# steps, 14:44-14:48), 2 ranks, the machine otherwise idle, code as committed with these rates (transforms over
# the ranks through mpi4py-fft, ``pfft``; history blocks of 16 steps). Kernels from -6 % to +79 % of each log,
# history from -26 % (the building at 108 m) to +23 % (the 1000 steps). t_kernel_byte is fitted to the seconds,
# not their ratios: on the H side a byte's first write cost 0.89-1.53 s/GB where a rank wrote at most 0.3 GB and
# 2.1-4.6 s/GB where it wrote 0.4-3 GB (0.91 s/GB in the 1000-step run: toeplitz_fit.py's column), so the large runs, where the term matters, are within -6 % to +20 % (the building at 72 m -3 % and -4 %,
# at 108 m -6 %) and the small ones over by 0.1-1.1 s (the paper's quarter model +63 %, the building at 36 m
# +79 %). Before it (t_pair_lag alone, fitted 2026-12-01 before the transforms went over the ranks) the
# building's kernels at 72 m and 108 m were -43 % and -45 % of these logs. The fit holds for the machine's hour:
# the same runs took up to twice as long in the slow spells of
# 2026-11-30 and 2026-12-01 (runs/building/README.md). r_sums, the real flops per second of the interpolated lags'
# weighted states anchor by anchor (``interp_products``: the multi-linear weights, small products), fitted with
# the history's other terms (the sites' logs). r_sums_span prices Chebyshev's, every anchor over the common span
# of states (one larger product a frequency, or two through the weights' rank, ``_low_rank``): the median over
# the logs that have it of the span's flops, as ``interp_work`` counts them, over the event SSI_BEM_HistInterp
# less its anchors' modelled kernel products (a model rate above dgemm's: the anchors' products are priced at
# r_products, slower than they run; not refitted 2026-12-03: no log of the fit has a Chebyshev span).
# fill_bytes: the step matrix's LU factors (MUMPS) per DOF and ln(DOF) (nested dissection of a surface grid:
# N log N entries; from one run, the 100 m site's two steps: 4.46 GB peak over the ranks with 2.16 GB estimated
# before this term, 2.3 GB of factors)
RATES = {"r_products": 1.89e10, "t_step_dof": 1.78e-7, "t_step_grid": 0.0, "t_step_elem": 8.73e-7,
         "t_pair_lag": 1.28e-6, "t_kernel_byte": 4.03e-9, "r_sums": 2.4e10, "fill_bytes": 1620.0, "g_pair_factor": 1.18,
         "r_sums_span": 4.82e10}
# The step matrix's LU on a uniform grid (``step_lu``, ``step_lu_of``: the estimate's factor_s and solve_s and the runs'
# loop predictions, BEM and coupled, where the dense
# model's c_fac N^1.5 and c_sol N ln N, fitted on small graded meshes, put the 72 m building's at 7.7 and 21.3 s
# against 5.3 and 12.1 s measured before the mirror blocks): entries in the factors E = step_fill n rho^2
# ln(n / rho^2) per independent block of n DOFs (rho = the step matrix's reach over the node spacing,
# ``geometric_reach``; a mirror-symmetric surface's 2 or 4 blocks, ``bem.mirror``), a step's
# solve t_solve_entry s an entry on 2 ranks (block low-rank from 20 000 DOFs, full rank below), the assembly and
# factorisation t_factor_entry s an entry. Fitted to the building's uniform grids (2026-11-30 06:33-06:38,
# jobscripts/building_uniform.sh, logs out/bench/building_uniform/uniform-36, -72, -72-fullrank; step_fill the
# geometric mean of E over the law on uniform-36 and -72 with and without the mirror blocks: 4.4-6.2)
STEP_RATES = {"step_fill": 5.3, "t_solve_entry": 5.8e-10, "t_factor_entry": 5.5e-8}


def step_lu(n_dofs, rho, blocks=1, ranks=2, kappa=0.107, rates=None):
    """(entries, factor seconds, seconds a solve) of the step matrix's LU (``STEP_RATES``) for ``n_dofs`` DOFs in
    ``blocks`` independent blocks, reach ``rho`` node spacings, on ``ranks`` ranks (a solve's time grows by
    1 + kappa (p - 1), the dense model's, relative to 2 ranks)."""
    r = dict(STEP_RATES, **(rates or {}))
    nb = n_dofs / max(int(blocks), 1)
    rho2 = max(float(rho), 1.0) ** 2
    entries = max(int(blocks), 1) * r["step_fill"] * nb * rho2 * np.log(max(nb / rho2, 2.0))
    solve = entries * r["t_solve_entry"] * (1.0 + kappa * (ranks - 1)) / (1.0 + kappa)
    return entries, entries * r["t_factor_entry"], solve


# The march's own work a step on the toeplitz store [s] beside its history sum and the step matrix's solve (the
# right-hand side, the sources, the recorder, the transforms' calls): 0.3-0.55 ms on 1 m grids of 4 x 4 and 8 x 8
# elements, 1 and 2 ranks, 2026-12-02, and 0.2-0.4 ms on 2026-12-03 (jobscripts/toeplitz_loop_check.py); the dense
# model's fitted c_step (0.59 ms, bem/cost.py) carries the dense store's own per-step work and over-predicted these
# loops by up to 1.8 times.
TZ_STEP_S = 3.5e-4


def loop_rest(cfg, n_steps, n_nodes):
    """Seconds of a toeplitz run's time loop beside the history sum and the step matrix's solves: the march's own
    work a step (TZ_STEP_S), a seismic wave's (``cost.source_step_seconds``: its free field on the nodes and a
    massless footing's correction) and the field snapshots (``cost.snapshot_seconds``). Without them a small
    grid's loop ran 2-8 times its prediction: 1 m grids of 4 x 4 and 8 x 8 elements, 200 steps, no snapshots,
    0.085-0.21 s against 0.022-0.106 s predicted at 1 and 2 ranks, and the default stride's snapshots 1.1-1.8 ms a
    step more (2026-12-02)."""
    from .cost import snapshot_seconds, snapshot_writes, source_step_seconds
    return ((TZ_STEP_S + source_step_seconds(cfg)) * int(n_steps)
            + snapshot_seconds(n_nodes) * snapshot_writes(cfg, n_steps))


def geometric_reach(cfg, prob):
    """The step matrix's reach from the geometry [m]: c_p t + the largest element diameter (t = 2 dt
    stabilised, dt plain: the last lag of the step matrix; an element a wave reaches within t couples all its
    nodes), an upper bound of the distance A couples (3.78 m against 3.5 m read off A on the uniform 72 m
    building, 2.46 against 2.12 m on the 24 m test grid). The coupled run and its estimate size the interface's
    region with it (``coupling.columns``), so that they take the same region."""
    X, cells = prob.mesh.nodes, prob.mesh.cells
    diam = float(np.linalg.norm(X[cells].max(axis=1) - X[cells].min(axis=1), axis=1).max()) if len(cells) else 0.0
    t = (2.0 if str(cfg.scheme).startswith("stabili") else 1.0) * prob.dt
    return prob.mat.cp * t + diam


def step_lu_of(cfg, prob, lat, ranks, kappa=None):
    """(entries, factorisation seconds, seconds a solve, reach in node spacings, blocks) of the soil's step
    matrix on the toeplitz store's uniform grid ``lat`` (``step_lu``: its reach, ``geometric_reach`` over the
    node spacing, and the mirror-symmetric blocks the run would use, ``mirror.blocks_of``), for ``petsc-ssi
    estimate`` and the runs' own predictions (BEM and coupled) alike; ``kappa`` (a solve's growth with the
    ranks): the estimate constants' (-ssi_estimate_constants) unless given."""
    from .mirror import blocks_of
    if kappa is None:
        from .cost import load_constants
        kappa = load_constants(cfg.get("estimate_constants", ""))[0].get("kappa", 0.107)
    nblk = blocks_of(prob) if str(cfg.get("step_mirror", "auto")).lower() != "off" else 1
    rho = geometric_reach(cfg, prob) / (0.5 * float(min(lat.h)))
    ent, fac, one = step_lu(3 * prob.mesh.n_nodes, rho, nblk, ranks, kappa=kappa)
    return ent, fac, one, rho, nblk


CHUNK_BYTES = 64e6      # the kernels are integrated and transformed at most this many bytes of lags at a time per rank


# the toeplitz store's steps a block (-ssi_history_block 0): a block reads each kernel once for its b steps; with both
# ranks on the memory bus a step's products got 1.5 x faster from b = 8 to 16 (runs/pekeris/README.md, roofline). The
# 72 m building's run (jobscripts/building_uniform.sh, uniform-72-area-exact, EXTRA="-ssi_history_block b",
# 2026-12-01 07:40, ``kept_rows``' slack then min(R / 2, 8 b)): the blocks' products 17.4, 11.7 and 9.3 s at b = 8,
# 16 and 32, the steps' own products 7.2, 8.9 and 11.0 s (a step reads the states of its block that the block's pass
# did not), the history sum 27.9, 23.9 and 23.4 s; the peak 6.17, 6.46, 6.67 GB
BLOCK = 16


def block_of(cfg):
    """The toeplitz store's steps a block: -ssi_history_block, or ``BLOCK`` with 0 (automatic)."""
    return int(cfg.get("history_block") or 0) or BLOCK


def chunk_bytes(kernel_bytes):
    """Bytes of real kernels a rank integrates and transforms at a time: a twentieth of ``kernel_bytes`` (the
    side's stored kernels on the rank that holds the most, ``_spectra``), between 8 MB and ``CHUNK_BYTES``. The
    build's transients (the chunk, its spectra, its integrals: 3 chunks on one rank, 1 + 6/p on p, ``estimate``)
    then stay a small share of the run's memory: with a
    fixed 64 MB the paper's quarter model peaked in the build, 1.70 GB over 2 ranks against 1.55 GB with
    16 MB, its kernels' seconds unchanged (3.59, 3.41 s against 3.70, 3.29 s); a 64 m grid keeps 64 MB
    (one lag's chunk took its kernels from 7.97 to 8.78 s, its peak unchanged)."""
    return float(min(CHUNK_BYTES, max(8e6, kernel_bytes / 20.0)))


def interp_work(plan, n_steps, block=BLOCK, stabilized=True):
    """(steps whose history reads an interpolating matrix, summed (anchors x states) of the weighted states
    over the run's blocks in products anchor by anchor, the same in products over all anchors' common span)
    of ``ToeplitzHistory`` with ``plan`` (``_spans`` on the weights of each block: the code's own choice;
    multi-linear weights go anchor by anchor, small products, Chebyshev's over the common span, one larger
    product a frequency, or its two products through the weights' rank where ``_low_rank`` takes them:
    their rates differ, ``RATES`` r_sums and r_sums_span); (0, 0, 0) without interpolation. The terms of a block's own states (T_L within a block) are left out (a few states a step)."""
    if plan is None or not plan.active:
        return 0, 0.0, 0.0
    from .interp import state_weights
    steps, work, span = 0, 0.0, 0.0
    R = plan.L
    for n0 in range(0, n_steps, block):
        C = np.zeros((block, plan.k, R))
        for i in range(block):
            n = n0 + 1 + i
            coef = state_weights(plan, n, stabilized)
            if coef is None:
                continue
            if n <= n_steps:
                steps += 1
            lo = n0 + 1 - R
            m = np.arange(max(lo, 1), min(n0, n - 1) + 1)
            C[i][:, m - lo] = coef[m].T
        sp = _spans(C)
        w = block * sum((j1 - j0) * (e - a) for j0, j1, a, e in sp)
        if len(sp) == 1 and sp[0][1] - sp[0][0] > 1:
            j0, j1, a, e = sp[0]
            _, _, W = _low_rank(C[:, j0:j1, a:e].reshape(-1, e - a))       # (the product through its rank)
            span += w if W is None else W.shape[0] * (block * (j1 - j0) + e - a)
        else:
            work += w
    return steps, work, span


def copies_dofs(lat, n_dofs, ranks, reach):
    """The DOFs of the ranks' copies of a state that lags 1-2's products read, summed over the ranks (``bsr.reader``):
    each rank's rows' nodes and, beyond each end of its range of nodes, ``reach`` node spacings (the step matrix's
    reach, ``geometric_reach`` over the node spacing) of rows of nodes (the longer of the lattice's two, 2 n + 1
    nodes: a bound); at most every DOF on every rank."""
    row = 2 * max(int(lat.nx), int(lat.ny)) + 1
    return float(min(ranks * n_dofs, n_dofs + 3.0 * (ranks - 1) * 2.0 * math.ceil(max(float(reach), 0.0)) * row))


def estimate(lat, L, n_steps, ranks=1, block=BLOCK, n_dofs=0, g_bytes=0.0, rates=None, plan=None, stabilized=True,
             glat=None, single=False, per_step=False, fft_ranks=0, reach=None):
    """(bytes over all ranks beside the processes themselves, seconds of the kernels' build, seconds of
    the history sum) of a toeplitz run. Per side (H on the grid ``lat``; G on ``glat``, the traction
    elements' window, ``traction_grid``, if any): kernels m complex per frequency (144 for H, 180 for G) for
    each exact lag (D: L, or the ``plan``'s Lx exact lags) and each of its k interpolating matrices, kept
    transforms 27 per frequency and kept state (``kept_rows``; float32 pairs with ``single``), each rank's slab
    in whole lane groups (``lanes.padded``: the products run over the padding too); the build's
    transients per rank (a chunk of kernels and its transforms' arrays: the larger side's; the ranks' slabs
    counted as the largest one, ``pfft.slab_counts`` with ``fft_ranks``), ``g_bytes``
    of G lags 1-2 and the step matrix, the march's past states (the ring and every rank's copy of it), the
    step matrix's LU factors (``fill_bytes`` n log n), with ``reach`` (node spacings) the copies of lags 1-2's
    columns as ``copies_dofs``; the history's complex products, 8 m flops per
    frequency and (step, kernel) pair at ``r_products`` per rank, the interpolated lags' weighted states
    (``interp_work``: 2 x 54 real flops per frequency, anchor and state) at ``r_sums`` anchor by anchor
    and ``r_sums_span`` over the anchors' common span, and
    ``t_step_dof`` per step and DOF. With ``per_step`` a fourth item: the history sum's seconds step by step
    (n_steps; their sum is the third item: step n's products read min(n - 1, D) exact kernels, the
    interpolating matrices' share and the sums spread evenly), the runs' progress model."""
    r = dict(RATES, **(rates or {}))
    active = plan is not None and plan.active
    D = int(plan.Lx) if active else int(L)
    k = int(plan.k) if active else 0
    W = kept_rows(int(L), block)
    # the march's ring of past states (march.Marcher: L + 2 + 31 deep, split over the ranks) and at most the
    # ranks' copies of the columns lags 1-2's panel products read (``_replicate``, ``rep_depth``: 2 + 3 + 32 states;
    # ``copies_dofs``: each rank's rows and a halo of ``reach`` node spacings, ``bsr.reader``; every DOF on every
    # rank without ``reach``): 8 bytes a DOF and state
    rep = ranks * n_dofs if reach is None else copies_dofs(lat, n_dofs, ranks, reach)
    ring = 8.0 * (n_dofs * (int(L) + 2 + 31) + rep * (2 + 3 + 32))
    factors = r["fill_bytes"] * n_dofs * math.log(max(n_dofs, 2))
    nbytes = float(g_bytes) + ring + factors
    build = t_build = sums = sums_span = kept = 0.0
    n = np.arange(1, n_steps + 1)
    ramp = np.zeros(n_steps)
    isteps, iwork, ispan = interp_work(plan, n_steps, block, stabilized)
    vbytes = 8.0 if single else 16.0
    for g, m in ((lat, 144), (glat, 180)):
        if g is None:
            continue
        # (each rank's slab in whole lane groups, ``pfft``'s whole columns of the half spectrum: the largest one on
        # every rank, so that the busiest rank's products and the most loaded node's memory are not averaged away;
        # -ssi_toeplitz_fft_ranks puts the frequencies on fewer ranks)
        Fl = ranks * padded(slab_counts(g.Mx, g.My, ranks, fft_ranks).max())
        per_lag = m * g.Mx * g.My * 8.0
        kp = 1.0 if is_point_symmetric(g) else 2.0          # (real kernels: half the bytes and the flops)
        kern = 8.0 * kp * Fl * m * (D + k)
        # (a rank's build transients in chunks: the chunk, its spectra and their k_y-major copy on one rank; on
        # more, the chunk, a row block of it and mpi4py-fft's four arrays and the copy, each 1/p of the chunk)
        copies = 3.0 if ranks == 1 else 1.0 + 6.0 / ranks
        build = max(build, ranks * copies * per_lag * max(1, min(D + k, int(chunk_bytes(kern / ranks) // per_lag))))
        nbytes += kern + vbytes * Fl * 27 * W
        kept += vbytes * Fl * 27 * W
        pairs = g.n_offsets if hasattr(g, "n_offsets") else 4 * (2 * g.nx) * (2 * g.ny)
        # (an offset and lag: its integrals, its planes' scatter, transforms and exchange, t_pair_lag for 9 slots: 5 of
        # them with real kernels; and the kernels' bytes, each written once into fresh memory, t_kernel_byte)
        t_build += (r["t_pair_lag"] * (5.0 if kp == 1.0 else 9.0) / 9.0 * pairs * (D + k) / ranks
                    * (r["g_pair_factor"] if m == 180 else 1.0) + r["t_kernel_byte"] * kern / ranks)
        ramp += 4.0 * kp * m * Fl * (np.minimum(np.maximum(n - 1, 0), D) + k * isteps / max(n_steps, 1))
        sums += 2.0 * 54 * Fl * iwork
        sums_span += 2.0 * 54 * Fl * ispan
    # per step, on every rank (fitted 2026-12-03 with the transforms over the ranks): the state's gather and the G
    # products (t_step_dof a DOF), the 27 + 12
    # transforms over the FFT grids of both sides (t_step_grid a grid point) and the transforms' inputs
    # element by element (t_step_elem a virtual element: a symmetric model's images count, so its step
    # costs nearly a whole model's for a quarter of the DOFs)
    grid = sum(g.Mx * g.My for g in (lat, glat) if g is not None)
    elems = sum(g.cell.size for g in (lat, glat) if g is not None)       # virtual elements: images too
    even = sums / (ranks * r["r_sums"]) + sums_span / (ranks * r["r_sums_span"])
    each = n_dofs * r["t_step_dof"] + grid * r["t_step_grid"] + elems * r["t_step_elem"]
    # (and the kept states' transforms, written once into fresh memory as the steps fill them: a cost a run pays
    # once, at the kernels' rate a byte, not every step: 1000 steps cost less a step than 300 on the same grid)
    t_hist = (float(ramp.sum()) / (ranks * r["r_products"]) + even + n_steps * each
              + min(n_steps / max(W, 1), 1.0) * r["t_kernel_byte"] * kept / ranks)
    if per_step:
        steps = (ramp / (ranks * r["r_products"]) + even / max(n_steps, 1) + each
                 + np.where(n <= W, r["t_kernel_byte"] * kept / ranks / max(W, 1), 0.0))
        return nbytes + build, t_build, t_hist, steps
    return nbytes + build, t_build, t_hist


# the largest part of a point-symmetric grid's rotated kernels that the symmetry makes zero, over their largest
# entry (round-off of the transforms; checked after the build, ``ToeplitzHistory._source``)
REAL_TOL = 1e-11


def point_sign(offsets, msigns):
    """The sign s of the kernels under the point reflection o -> -o (``mirror_signs``' flip 3, the same for every
    pattern entry: -1 for H's, +1 for G's) when the offsets (``kernel_offsets``) are the same set reflected, else
    0: a whole grid's H side (every node reads every element) is; a symmetric model's quarter of nodes, or a
    traction window off the grid's centre, is not."""
    s = np.unique(np.asarray(msigns)[3])
    return int(s[0]) if s.size == 1 and _reflected_alike(offsets) else 0


def _reflected_alike(offsets):
    """Whether the offsets (``kernel_offsets``' rows, in half element sizes) are the same set reflected through
    the origin."""
    o = np.asarray(offsets)[:, :2]
    return bool(len(o)) and np.array_equal(np.unique(o, axis=0), np.unique(-o, axis=0))


def is_point_symmetric(lat):
    """Whether a side's grid (``Lattice``, or the traction window's) has point-symmetric kernel offsets, so that
    its kernels are real (``point_sign``; H's sign, with the flat pattern's every entry alike); kept on the
    lattice (``point_symmetric``) once known."""
    got = getattr(lat, "point_symmetric", None)
    if got is None:
        got = _reflected_alike(kernel_offsets(lat))
        try:
            lat.point_symmetric = got
        except AttributeError:
            pass
    return got


def kept_rows(R, b):
    """Rows of the kept transforms' buffers (``ToeplitzHistory._room``) for a history of reach R and blocks of b
    steps: the R states a block reads back, its own b, and a slack that sets how often the kept ones move to the
    start (R rows copied each time): every 2 b + 9 + E steps with 3 b + 8 + E rows beyond R, E = min(R / 2, 8 b,
    64) (the 72 m building: R = 207, E = 64, every 89 steps at b = 8 instead of every 25 with E = 0, for 64 more rows
    of both sides' transforms, 0.29 GB over the ranks). The cap of 64 came with the default block of 16: E =
    min(R / 2, 8 b) took the paper's quarter model's peak (-memory_view) from 1.46 GB at b = 8 to 1.50 GB at 16
    (1.53 GB in a later run), over the 1.5 GB issue 41 asks; 1.476 GB in two runs with the cap."""
    return int(R) + 3 * int(b) + 8 + min(int(R) // 2, 8 * int(b), 64)


def kernel_offsets(lat):
    """The collocation points of the kernels relative to an element of the lattice: per class t the
    lattice offsets k = i' - i a node of that class (at i') and an input element (at i, in the grid's
    input box ``in_lo``, ``in_n``) can have, (points (n, 2) in half element sizes, class, kx, ky); offsets
    no node reads are left out (their kernel is zero: the outputs they reach are no node's)."""
    out = []
    nf = lat.node_fine
    (lx, ly), (nx, ny) = lat.in_lo, lat.in_n
    for t, (tx, ty) in enumerate(CLASSES):
        sel = ((nf[:, 0] & 1) == tx) & ((nf[:, 1] & 1) == ty)
        if not np.any(sel):
            continue
        ix = (nf[sel, 0] - tx) // 2
        iy = (nf[sel, 1] - ty) // 2
        kx = np.arange(ix.min() - (lx + nx - 1), ix.max() - lx + 1)
        ky = np.arange(iy.min() - (ly + ny - 1), iy.max() - ly + 1)
        KX, KY = np.meshgrid(kx, ky, indexing="ij")
        out.append(np.c_[2 * KX.ravel() + tx, 2 * KY.ravel() + ty, np.full(KX.size, t), KX.ravel(), KY.ravel()])
    return np.concatenate(out)


# the G side's window is widened to the lattice's centred box when its FFT grid then grows by at most this factor:
# its kernels become real (``point_sign``), half the bytes and products a frequency
CENTRED_GROWTH = 1.5


def traction_grid(lat, VT):
    """The G side's grid: ``lat``'s window on the virtual elements with a traction column (VT: their
    traction columns, -1 none), its kernel offsets counted (``n_offsets``); None without tractions. Where the
    window centred on the lattice that holds it has point-symmetric offsets (the outputs a whole grid's
    nodes) and an FFT grid at most ``CENTRED_GROWTH`` times the window's, that window (its kernels real, the
    elements without tractions in it read as zeros)."""
    sel = np.any(np.asarray(VT) >= 0, axis=1)
    if not sel.any():
        return None
    g = lat.window(sel)
    N = (lat.nx, lat.ny)
    lo = tuple(min(g.in_lo[ax], N[ax] - g.in_lo[ax] - g.in_n[ax]) for ax in (0, 1))     # (the centred box)
    n = tuple(N[ax] - 2 * lo[ax] for ax in (0, 1))
    if (lo, n) != (tuple(g.in_lo), tuple(g.in_n)):
        c = lat.window_box(lo, n)
        if c.F <= CENTRED_GROWTH * g.F and is_point_symmetric(c):
            g = c
    g.n_offsets = len(kernel_offsets(g))
    return g


@njit(cache=True)
def _windows(pts, X, c0, R0, h0, reach, alpha, beta, dt, L, lag_lo, toff, tol, ns_base, ns_max, near, c_lo, c_hi):
    """meta rows (lo, hi, sing, ns, 0, 0) of ``integrate_records`` for the points ``pts`` against
    element X, the lags c_lo..c_hi of the windows of an assembly of lags lag_lo..L (a singular pair
    from its first lag: its subdivisions are those of that assembly); keep[i] False: no lag."""
    n = pts.shape[0]
    meta = np.zeros((n, 6), np.int64)
    keep = np.zeros(n, np.bool_)
    for i in range(n):
        lo, hi, sing, ns = _pair_window(pts[i], X, c0, R0, h0, reach, alpha, beta, dt, L, lag_lo, toff, tol,
                                        ns_base, ns_max, near)
        if sing < 0:
            lo = max(lo, c_lo)
        hi = min(hi, c_hi)
        if lo > hi or hi < c_lo:
            continue
        meta[i, 0] = lo
        meta[i, 1] = hi
        meta[i, 2] = sing
        meta[i, 3] = ns
        keep[i] = True
    return meta, keep


# the two sides of the history sum (``ToeplitzHistory.side``): H on the displacements (flat pattern H4: x, y
# out of z in and z out of x, y in; subtracted) and G on the tractions (G5: x, y out of x, y in and z out of z
# in; added). Per side: the pattern's entries, the output columns of the products with the 9-row (z input)
# and the 18-row (x, y input) kernels, and the sign of its terms in the history sum
SIDES = {"u": {"m": 4, "n9": 8, "n18": 4, "sign": -1.0, "what": "H"},
         "p": {"m": 5, "n9": 4, "n18": 8, "sign": 1.0, "what": "G"}}
PRECISIONS = {"double": np.float64, "single": np.float32}


class ToeplitzHistory:
    """Collective: one side of the history sum of a uniform flat grid in Fourier space (module
    docstring): ``side`` "u" the H lags on the displacements (the grid ``lat``), "p" the G lags on the
    tractions (``lat`` the window of the traction elements, ``traction_grid``). ``build`` computes the
    kernels; ``add(n, march, out_u)`` adds this side's terms of step n's history sum to ``out_u``. The
    kept states' transforms in ``precision`` (double, or single: half their memory, the products still in
    double)."""

    def __init__(self, comm, ls, lat, log=printf, block=BLOCK, side="u", precision="double", fft_ranks=0):
        self.comm, self.ls, self.lat, self.log = comm, ls, lat, log
        self.side, self.spec = side, SIDES[side]
        self.vdtype = PRECISIONS[precision]
        self.block = max(1, int(block))     # steps whose known-state products share one pass over the kernels
        self._blk = None
        # the 2-D FFTs over the ranks (``pfft``, mpi4py-fft): this rank's rows of the grid and its frequencies
        # (k_y-major: f0..f1 of the spectrum in that order, ``pfft.kx_ky``)
        from .pfft import SlabFFT
        self.fft = SlabFFT(comm.tompi4py(), lat.Mx, lat.My, fft_ranks)
        self.f0, self.f1 = self.fft.f0, self.fft.f1
        self.upto = 0
        # this rank's seconds of the build's parts (the log's breakdown, ``build_text``; the model's terms,
        # ``estimate``): the element integrals, their scatter into the chunk's planes, the planes' sums over the
        # ranks and their transforms (``_reduce_transform``), and the spectra written into the kernels' lanes
        self.phases = dict.fromkeys(("integrals", "planes", "transforms", "weights"), 0.0)

    # ---------------------------------------------------------------- kernels
    def _integrate(self, lag_lo, c_lo, c_hi, toff, L, sel):
        """The element integrals at the mirror offsets ``sel`` (indices into ``self.mirror``: offsets in
        half element sizes, both >= 0, ``mirror_offsets``) for lags c_lo..c_hi at kernel time l dt + toff,
        with the windows, subdivisions and singular treatment of the dense assembly of lags lag_lo..L
        (``_pair_window``); a singular pair (its point a node of the element) from lag_lo on, as that
        assembly integrates it. Returns (mirror offsets kept, meta, pool offsets, pool): the H integrals' (P)
        pool on the u side, the G integrals' (U) on the p side."""
        from .assemble import integrate_records, SING_TOL, plane
        ls, lat = self.ls, self.lat
        o = ls.opts
        v0 = 0
        X = ls.VX[v0:v0 + 1]
        c0, R0, h0 = ls.Vc[v0], ls.VR[v0], ls.Vh[v0]
        gq, gw = np.polynomial.legendre.leggauss(o["gauss"])
        gr, gwr = np.polynomial.legendre.leggauss(o["singular_order"])
        mat, dt = ls.mat, ls.dt
        reach = mat.cp * (dt * L + toff)
        pts = np.zeros((len(sel), 3))
        off = self.mirror[sel]
        pts[:, 0] = c0[0] + off[:, 0] * 0.5 * lat.h[0]
        pts[:, 1] = c0[1] + off[:, 1] * 0.5 * lat.h[1]
        pts[:, 2] = c0[2]
        meta, keep = _windows(pts, X[0], c0, R0, h0, reach, mat.cp, mat.cs, dt, L, lag_lo, toff, SING_TOL,
                              int(o["subdivisions"]), int(o["max_subdivisions"]), float(o["near_factor"]), c_lo, c_hi)
        meta, pts, idx = meta[keep], pts[keep], np.asarray(sel)[keep]
        meta[:, 4] = 2 if self.side == "p" else 0            # (want_u: 2 the G integrals alone, 0 the H ones)
        if not hasattr(self, "_plane") or self._plane is None:
            self._plane = plane(ls.in_plane, X, int(o["subdivisions"]), gq, gw, int(o["max_subdivisions"]))
        dropped = np.zeros(2)
        offP, P, offU, U, nev = integrate_records(meta, pts, X, c_hi, dt, mat.cp, mat.cs, mat.rho, mat.nu, gq, gw,
                                                  gr, gwr, toff, float(ls.Vh.min()), ls.pattern(), dropped,
                                                  int(o["subdivisions"]), self._plane)
        from mpi4py import MPI
        lost = self.comm.tompi4py().allreduce(float(dropped.max()), op=MPI.MAX)    # (every rank: no hang)
        if lost != 0.0:
            raise SSIError(f"-ssi_lag_store toeplitz: a flat-surface block entry outside its pattern is "
                           f"{lost:.3g}, not 0; report this with the mesh")
        self.nev += int(nev)
        return (idx, meta, offU, U) if self.side == "p" else (idx, meta, offP, P)

    def _spectra(self, lag_lo, lag_hi, toff, L):
        """Yield (lag, this rank's slab of the lag's kernel spectra (4, 9, m, slab) complex: class, slot,
        pattern entry, frequency) for lags lag_lo..lag_hi, integrated in chunks of lags (the integrals split
        over the ranks by offset, summed: each offset is integrated by one rank, so the sum is exact; the
        planes summed onto the ranks of their rows and transformed over the ranks, ``_reduce_transform``)."""
        lat = self.lat
        m = self.spec["m"]
        mpi = self.comm.tompi4py()
        p, r = mpi.Get_size(), mpi.Get_rank()
        sel = np.arange(r, len(self.mirror), p)          # (each mirror offset integrated by one rank)
        mine = np.full(len(self.mirror), -1, np.int64)
        per_lag = 4 * (5 if self.real else 9) * m * lat.Mx * lat.My * 8
        # (the same chunk on every rank: each chunk is one set of collective reductions and transforms, and the
        # ranks' slabs differ, so their own kernels' bytes may not give the same chunk)
        from mpi4py import MPI
        kern = mpi.allreduce(sum(a.nbytes for a in (self.K9, self.K18, self.A9, self.A18)), op=MPI.MAX)
        chunk = max(1, min(lag_hi - lag_lo + 1, int(chunk_bytes(kern) // per_lag)))
        t = self.offsets[:, 2]
        kx = np.mod(self.offsets[:, 3] + lat.in_lo[0], lat.Mx)      # (inputs placed from lattice index in_lo)
        ky = np.mod(self.offsets[:, 4] + lat.in_lo[1], lat.My)
        ph = self.phases
        for c_lo in range(lag_lo, lag_hi + 1, chunk):
            c_hi = min(lag_hi, c_lo + chunk - 1)
            t0 = time.perf_counter()
            idx, meta, offP, P = self._integrate(lag_lo, c_lo, c_hi, toff, L, sel)
            t1 = time.perf_counter()
            mine[:] = -1
            mine[idx] = np.arange(len(idx))
            Kp = np.zeros((c_hi - c_lo + 1, 4, 5 if self.real else 9, m, lat.Mx, lat.My))
            _scatter_kernels(Kp, c_lo, mine[self.mirror_of], self.flip, meta, offP, P, t, kx, ky, lat.code0,
                             MIRROR_SLOTS, self.mirror_signs)
            t2 = time.perf_counter()
            S = self._reduce_transform(Kp)
            Kp = None
            ph["integrals"] += t1 - t0
            ph["planes"] += t2 - t1
            ph["transforms"] += time.perf_counter() - t2
            for i in range(c_hi - c_lo + 1):
                yield c_lo + i, S[i]
            S = None

    def _reduce_transform(self, Kp):
        """Collective: this rank's slab (nl, 4, 9, m, slab) of the 2-D real FFTs of the ranks' summed
        kernels, Kp (nl, 4, 9, m, Mx, My) this rank's offsets' share. Each row block of the planes is summed
        onto the rank of those rows (one MPI Reduce a block), and mpi4py-fft transforms the planes over the
        ranks (``pfft.SlabFFT``: its own all-to-all between its two passes), so that each rank ends with its
        frequencies of every plane; no rank holds a whole chunk's spectra, and each of the q ranks that
        transform (``pfft.members``) makes 1/q of the transforms' work."""
        from mpi4py import MPI
        lat, fft = self.lat, self.fft
        shape = Kp.shape[:4]
        nch = int(np.prod(shape))
        K3 = Kp.reshape(nch, lat.Mx, lat.My)
        mpi = self.comm.tompi4py()
        r = mpi.Get_rank()
        if mpi.Get_size() == 1:         # (one rank: scipy's transform of the chunk as it is, no copy into a plan's
            from scipy.fft import rfft2     # arrays: 3.2-3.8 s against 4.94 s of kernels, 1.55 against 1.79 GB on the
            S = rfft2(K3, axes=(-2, -1), workers=1)     # paper's whole case, jobscripts/README.md)
        else:
            fft.forget(keep=(nch,))                     # (one chunk size's plan at a time: the last chunk's, the
            In = fft.inputs(nch)                        # anchors' single lags are other sizes)
            for q, (a, b) in enumerate(fft.rows_of):    # (a block of rows at a time: 1/p of the chunk's copy)
                if b > a:
                    blk = np.ascontiguousarray(K3[:, a:b])
                    mpi.Reduce(blk, In if q == r else None, op=MPI.SUM, root=q)
                    blk = None
            S = fft.transform(nch)                      # (nch, Mx, k_y columns)
        return np.ascontiguousarray(S.transpose(0, 2, 1)).reshape(shape + (-1,))     # this rank's slab, k_y-major

    def _terms(self, march):
        """{key: [(time distance d, coefficient)]}: the history terms this side takes (``Marcher._step_terms``
        of a step past the lags' reach), all but those of a lag whose Mat the march holds (lag 2: the
        step matrix's lags are Mats, and the march applies their history terms)."""
        nbig = self.ls.L + 8
        by_key = {}
        for key, m, c in march._step_terms(nbig):
            if march._mat(key, self.side) is not None:
                continue
            by_key.setdefault(key, []).append((nbig - m, c))
        return by_key

    def build(self, march, plan, monitor=False, kernels=None):
        """Collective: the kernels K'_d (d = 1..D) of the march's exact lags and the kernels A_j of the
        interpolating lags (``plan``: the far lags' matrices are sum_j w_j(l) M(T_j), so their part of the
        history sum is sum_j A_j (sum_m c_j(n, m) v^m), the weights c of ``Marcher._interp_coef``, formed
        per block over the kept transforms: only the exact and the anchors' kernels are stored), in this
        rank's frequency slab. ``kernels``: {K9, K18, A9, A18} this rank's arrays as a run saved them
        (-ssi_lags_load, ``lagstore``): taken as they are, nothing integrated (their shapes checked)."""
        t0 = time.perf_counter()
        self.offsets = kernel_offsets(self.lat)
        self.lat.n_offsets = len(self.offsets)
        self.mirror, self.mirror_of, self.flip = mirror_offsets(self.offsets)
        hp, hq, gp, gq = self.ls.pattern()[:4]
        self.mirror_signs = mirror_signs(*((hp, hq) if self.side == "u" else (gp, gq)))
        # the kernels real where the offsets are point-symmetric (``point_sign``): per slot pair (a, 8 - a) the
        # real parts of the rotated sum and difference spectra, the states as their sums and differences
        self.sg = point_sign(self.offsets, self.mirror_signs)
        self.real = self.sg != 0
        self.rot_k = self._rotation(+1) if self.real else None
        self.dropped = self.kept = 0.0
        self.nev = 0
        self.phases = dict.fromkeys(self.phases, 0.0)
        by_key = self._terms(march)
        D = max([d for (kind, _), v in by_key.items() if kind == "x" for d, _ in v] + [0])
        self.D = D
        # the history's reach: the oldest state a step reads (the interpolated lags' reach beyond D)
        self.R = max([d for v in by_key.values() for d, _ in v] + [0])
        self.k = plan.k if plan is not None and plan.active else 0
        slab = self.f1 - self.f0
        n9, n18 = self.spec["n9"], self.spec["n18"]
        # per frequency two dense matrices, rows (d descending, slot, input component), columns (class,
        # output component): K9 (z in; H: x, y out, entries xz, yz; G: z out, zz), K18 (x, y in; H: z out,
        # zx, zy; G: x, y out, xx, xy, yx, yy): the flat pattern's entries of every block, no zeros (``_kernel_blocks``);
        # the anchors' A9, A18 the same with rows (anchor j, slot, input component)
        # (in frequency lanes, ``lanes.to_lanes``: (groups, rows, columns, 2, FW) real)
        G = n_groups(slab)
        kp = 1 if self.real else 2                  # (a real kernel: one part a column)
        self.K9 = np.zeros((G, D * 9, n9, kp, FW))
        self.K18 = np.zeros((G, D * 18, n18, kp, FW))
        self.A9 = np.zeros((G, self.k * 9, n9, kp, FW))
        self.A18 = np.zeros((G, self.k * 18, n18, kp, FW))
        self._fill_kernels(by_key, plan, kernels)
        self.fft.forget()               # (the chunks' plans and arrays; the steps' are made with zeros below)
        # the kept states' transforms, in time order (state m at m - base), in lanes: z (groups, W, 9, 2, FW),
        # x and y (groups, W, 18, 2, FW); a step's window of D states is a run of rows of each group (a row
        # offset for ``lanes.lane_products``, no copy); states before the first are zeros, as are those not
        # yet made
        self.W = kept_rows(self.R, self.block)
        self.V9 = np.zeros((G, self.W, 9, 2, FW), self.vdtype)
        self.V18 = np.zeros((G, self.W, 18, 2, FW), self.vdtype)
        self.base = -self.R
        self._setup_state_maps(march)
        if self.real:
            from mpi4py import MPI
            mpi = self.comm.tompi4py()
            dropped, kept = mpi.allreduce(self.dropped, op=MPI.MAX), mpi.allreduce(self.kept, op=MPI.MAX)
            if not dropped <= REAL_TOL * kept:          # (every rank: the same numbers)
                raise SSIError(f"-ssi_lag_store toeplitz: the {self.spec['what']} kernels of a point-symmetric grid "
                               f"have a part {dropped:.3g} ({dropped / max(kept, 1e-300):.3g} of their largest) "
                               "that should be zero; report this with the mesh")
            self.rot_out = self._rotation(-1)
        from ..sysmem import release_freed
        release_freed()         # the chunks' integrals and spectra, freed into the C heap: not resident in the run
        self.t_build = time.perf_counter() - t0
        mpi = self.comm.tompi4py()
        self.nev = mpi.allreduce(self.nev)
        self.bytes = mpi.allreduce(sum(a.nbytes for a in (self.K9, self.K18, self.A9, self.A18, self.V9, self.V18)))
        return self

    def build_text(self):
        """'kernels T s: integrals a s, planes b s, transforms c s, weights d s': the build's wall and this rank's
        parts (``phases``; the rest, the set-up and the kernels' release, is the difference)."""
        parts = ", ".join(f"{k} {v:.3g} s" for k, v in self.phases.items())
        return f"kernels {self.t_build:.3g} s: {parts}"

    def _fill_kernels(self, by_key, plan, kernels=None):
        """Collective: K9, K18 (the exact lags' kernels, ``by_key``'s terms ("x", lag): [(d, c)], each lag's
        spectra weighted into the time distances d it serves) and A9, A18 (the interpolating matrices' anchors,
        ("i", j)), integrated and transformed chunk by chunk (``_spectra``); or ``kernels`` as a run saved
        them (-ssi_lags_load), their shapes checked on every rank."""
        D = self.D
        exact = sorted(j for kind, j in by_key if kind == "x")
        plan_k = self.k
        if kernels is not None:
            bad = [n for n in ("K9", "K18", "A9", "A18") if n not in kernels
                   or kernels[n].shape != getattr(self, n).shape] + (["F"] if kernels.get("F", self.lat.F) != self.lat.F
                                                                     else []) \
                + (["grid"] if tuple(kernels.get("grid", (self.lat.Mx, self.lat.My))) != (self.lat.Mx, self.lat.My) else [])
            from mpi4py import MPI
            if self.comm.tompi4py().allreduce(len(bad), op=MPI.MAX):
                raise SSIError(f"-ssi_lags_load: the file's {self.spec['what']} kernels do not have this run's shapes "
                               "or spectrum (saved by another version of petsc-ssi?): save them again with -ssi_lags_save")
            for n in ("K9", "K18", "A9", "A18"):        # (the loaded arrays adopted: no second copy)
                setattr(self, n, np.ascontiguousarray(kernels[n], dtype=np.float64))
            exact, plan_k = [], 0
        if exact:
            # per time distance d its lags' weights, in lag order: a row block is written once, when its last lag's
            # spectra are made (the stabilised scheme weighs each lag into about three distances); a lag's spectra
            # stay in a ring of slots until the last distance that weighs it is written
            into = {}
            for lag in exact:
                for d, c in by_key[("x", lag)]:
                    into.setdefault(d, []).append((lag, float(c)))
            last = {}
            for d, v in into.items():
                last.setdefault(v[-1][0], []).append(d)
            ring = 1 + max(v[-1][0] - v[0][0] for v in into.values())
            src = None
            assert all(1 <= d <= D for d in into), "toeplitz: a distance outside the kernels' rows"   # (put_spectra
            for lag, S in self._spectra(1, max(exact), 0.0, max(exact)):                         # checks no bounds)
                if ("x", lag) not in by_key:
                    continue
                t0 = time.perf_counter()
                if src is None:
                    src = np.empty((ring, 4 * 9 * S.shape[2], S.shape[-1]), np.float64 if self.real else np.complex128)
                self._source(S, out=src[lag % ring])
                for d in sorted(last.get(lag, ())):
                    sel = np.array([l_ % ring for l_, _ in into[d]], np.int64)
                    c = np.array([c for _, c in into[d]])
                    put_spectra(self.K9, 9 * (D - d), src, sel, self._idx[0], c)
                    put_spectra(self.K18, 18 * (D - d), src, sel, self._idx[1], c)
                self.phases["weights"] += time.perf_counter() - t0
            src = None
        slot0, one = np.zeros(1, np.int64), np.ones(1)          # (an anchor's kernel: its one lag, weight 1)
        for i in range(plan_k):
            if ("i", i) not in by_key:          # (no lag of the run weighs this matrix: its kernel stays 0)
                continue
            lag, toff = plan.kernel_time(i)
            for _, S in self._spectra(lag, lag, toff, lag):
                t0 = time.perf_counter()
                src = self._source(S)[None]
                put_spectra(self.A9, 9 * i, src, slot0, self._idx[0], one)
                put_spectra(self.A18, 18 * i, src, slot0, self._idx[1], one)
                self.phases["weights"] += time.perf_counter() - t0

    def _rotation(self, sign):
        """(4, frequencies) complex: exp(sign i psi_t(f)) per class t over this rank's slab,
        psi_t(f) = pi (f_x (2 lo_x - t_x) / M_x + f_y (2 lo_y - t_y) / M_y): the point reflection o -> -o of class
        t's offsets maps the FFT grid's index j to 2 lo - t - j (lo: the inputs' lattice box ``in_lo``), so a
        slot's spectrum and its mirror's are K_{8-a}(f) = s exp(-2 i psi_t(f)) conj(K_a(f)); exp(i psi) K is
        then real on the pairs' sums (``_source``)."""
        from .pfft import kx_ky
        lat = self.lat
        fx, fy = kx_ky(lat.Mx, lat.My, self.f0, self.f1)
        out = np.empty((4, fx.size), np.complex128)
        for t, (tx, ty) in enumerate(CLASSES):
            psi = np.pi * (fx * (2 * lat.in_lo[0] - tx) / lat.Mx + fy * (2 * lat.in_lo[1] - ty) / lat.My)
            out[t] = np.exp(sign * 1j * psi)
        return out

    def _source(self, S, out=None):
        """One lag's spectra S (4 classes, 9 slots, m entries, slab) as the rows (class, slot, entry) x slab that
        ``lanes.put_spectra`` writes into the kernels' lanes by ``_idx`` (``_kernel_blocks``' rows and columns):
        complex, or on a point-symmetric grid real from the slots 0..4 only (S (4, 5, m, slab)): with
        h = exp(i psi_t) (``_rotation``) and the sign s of the point reflection (``point_sign``), the pair
        (a, 8 - a), a < 4, has h (K_a + s K_{8-a}) / 2 = Re(h K_a) and h (K_a - s K_{8-a}) / 2 = i Im(h K_a)
        (s K_{8-a} = exp(-2 i psi_t) conj(K_a)): slots 2 a and 2 a + 1 are the real and the imaginary part of
        h K_a, slot 8 the centre's h K_4, real part (s = 1) or imaginary (s = -1); the centre's other part is zero
        by the symmetry (its largest kept in ``dropped``, checked after the build: the phases' and signs' check).
        ``out``: the array (rows, slab) to write them into (a slot of the build's ring)."""
        if getattr(self, "_idx", None) is None:
            m = S.shape[2]
            self._idx = tuple(np.ascontiguousarray(B[0], np.int64)
                              for B in _kernel_blocks(np.arange(4 * 9 * m).reshape(4, 9, m, 1)))
        if not self.real:
            if out is None:
                return np.ascontiguousarray(S).reshape(int(np.prod(S.shape[:-1])), S.shape[-1])   # (a slab may be empty)
            out[...] = S.reshape(out.shape)
            return out
        h = self.rot_k[:, None, :]                                        # (4, 1, slab)
        R = np.empty(S.shape[:1] + (9,) + S.shape[2:]) if out is None else out.reshape(S.shape[:1] + (9,) + S.shape[2:])
        sg = self.sg
        for a in range(4):
            z = h * S[:, a]
            R[:, 2 * a], R[:, 2 * a + 1] = z.real, z.imag
        c = h * S[:, 4]
        R[:, 8] = c.real if sg > 0 else c.imag
        self.dropped = max(self.dropped, float(np.abs(c.imag if sg > 0 else c.real).max(initial=0.0)))
        self.kept = max(self.kept, float(np.abs(R).max(initial=0.0)))
        return R.reshape(int(np.prod(R.shape[:-1])), R.shape[-1])

    def _pairs(self, S):
        """A state's slab S (9 slots, 3 components, slab) as the real kernels read it: rows 2 a, 2 a + 1 the
        pair (a, 8 - a)'s v_a + s v_{8-a} and i (v_a - s v_{8-a}), row 8 the centre's v_4 (s = 1) or i v_4."""
        sg = self.sg
        P = np.empty_like(S)
        for a in range(4):
            P[2 * a] = S[a] + sg * S[8 - a]
            P[2 * a + 1] = 1j * (S[a] - sg * S[8 - a])
        P[8] = S[4] if sg > 0 else 1j * S[4]
        return P

    def _setup_state_maps(self, march):
        """Per step, what this rank transforms and where its sums go (``pfft``: the rows x0..x1 of the FFT grid
        are this rank's). In: the input elements of the grid (their lattice position from in_lo) in this rank's
        rows, their 9 slots' rows of this rank's copy of the nodes they read (a PETSc scatter of those nodes of
        the side's state, u or p: reshaped (-1, 3); -1 for a slot without a traction column) and image signs.
        Out: a PETSc scatter from every rank's rows of the inverse transforms (12 planes, class t and component,
        x0..x1 by My each) to the rows of out_u, each row's value from its class's plane at its FFT grid
        position."""
        lat, ls = self.lat, self.ls
        PETSc = march.PETSc
        fft = self.fft
        x0, x1 = fft.rows
        tmpl = march.u_tmpl if self.side == "u" else march.p_tmpl
        # v_a(cell) = S_v u(VN[v, perm[v, a]]) (or S_v p(VT[v, perm[v, a]])): for every input element and slot
        src = ls.VN if self.side == "u" else ls.VT
        vidx = src[np.arange(len(src))[:, None], lat.perm]                  # (nv, 9)
        cell = lat.cell
        vx = cell // lat.ny - lat.in_lo[0]
        use = np.any(vidx >= 0, axis=1) & (vx >= x0) & (vx < x1)
        nodes, inv = np.unique(vidx[use], return_inverse=True)
        inv = inv.reshape(-1, 9)
        neg = nodes < 0                                                      # (-1 first when present)
        self.vnode = np.where(neg[inv], -1, inv - int(neg.sum())).astype(np.int64)
        nodes = nodes[~neg]
        self.vsign = ls.VS[use]                                              # (nv, 3)
        self.vpos = (vx[use] - x0, cell[use] % lat.ny - lat.in_lo[1])
        dofs = (3 * nodes[:, None] + np.arange(3)).ravel().astype(PETSc.IntType)
        self.seq = PETSc.Vec().createSeq(len(dofs), comm=PETSc.COMM_SELF)
        isf = PETSc.IS().createGeneral(dofs, comm=PETSc.COMM_SELF)
        self.sc = PETSc.Scatter().create(tmpl, isf, self.seq, None)
        isf.destroy()
        # (the transform's own input array, zeroed: only the slots' cells are written, the other zeros stay, its
        # plan preserving its input)
        self._grid = fft.inputs(27).reshape(9, 3, x1 - x0, lat.My)
        self._grid[...] = 0.0
        if fft.member and not np.shares_memory(self._grid, fft.inputs(27)):
            raise SSIError("-ssi_lag_store toeplitz: mpi4py-fft's input array is not contiguous; report this")
        # out: row i of out_u (this rank's nodes, class t, grid position (x, y)) from plane (t, c) of the rank
        # whose rows hold x
        r0, r1 = march.u_tmpl.getOwnershipRange()
        rows = np.arange(r0 // 3, r1 // 3)
        nf = lat.node_fine[rows]
        tx, ty = nf[:, 0] & 1, nf[:, 1] & 1
        row_t = (2 * tx + ty).astype(np.int64)
        row_x = np.mod((nf[:, 0] - tx) // 2, lat.Mx)
        row_y = np.mod((nf[:, 1] - ty) // 2, lat.My)
        lo = np.array([a for a, _ in fft.rows_of])
        nx = np.array([b - a for a, b in fft.rows_of])
        start = np.r_[0, np.cumsum(12 * nx * lat.My)[:-1]]
        k = np.searchsorted(lo, row_x, side="right") - 1   # (the rank of row x: the ranks without rows start at Mx)
        c = np.arange(3)
        gidx = start[k][:, None] + ((3 * row_t[:, None] + c) * nx[k][:, None] + (row_x - lo[k])[:, None]) * lat.My \
            + row_y[:, None]
        self.gvec = PETSc.Vec().createWithArray(fft.outputs(12).reshape(-1), comm=self.comm)   # (the inverse's output)
        if fft.member and not np.shares_memory(self.gvec.getArray(readonly=True), fft.outputs(12)):
            raise SSIError("-ssi_lag_store toeplitz: the scatter's Vec does not wrap mpi4py-fft's output; report this")
        self.ovec = march.u_tmpl.duplicate()
        isf = PETSc.IS().createGeneral(gidx.ravel().astype(PETSc.IntType), comm=self.comm)
        ist = PETSc.IS().createStride(r1 - r0, first=r0, step=1, comm=self.comm)
        self.osc = PETSc.Scatter().create(self.gvec, isf, self.ovec, ist)
        isf.destroy()
        ist.destroy()

    # ---------------------------------------------------------------- per step
    def _transform(self, u_loc, m):
        """State m's transform, this rank's slab, into row m - base of the kept lanes: the state's values on
        this rank's rows of the FFT grid per slot and component (``lanes.scatter_slots``, from this rank's copy
        of the nodes they read), 27 real 2-D FFTs over the ranks (``pfft``: this rank's frequencies), the slab
        put into lanes (``lanes.put_state_grid``)."""
        U = u_loc.reshape(-1, 3)
        ix, iy = self.vpos
        scatter_slots(U, self.vnode, self.vsign, ix, iy, self._grid)
        S = self.fft.transform(27)
        S = S.reshape((9, 3) + S.shape[1:])                # (slot, component, k_x, k_y column)
        put_state_grid(self._pairs(S) if self.real else S, self.V9, self.V18, m - self.base)

    def reset(self):
        """Forget every kept transform (a restart's rewind: they are made again from the march's states)."""
        self.upto, self.base, self._blk = 0, -self.R, None
        self.V9[...] = 0.0
        self.V18[...] = 0.0

    def _room(self, n0):
        """Before the block of steps n0 + 1 .. n0 + b: the buffers hold states n0 + 1 - R .. n0 + b (R the
        history's reach); when they would run past the end, the kept ones move to the start and the rest is
        zeroed."""
        if n0 + self.block - self.base < self.W:
            return
        lo = n0 + 1 - self.R
        keep = slice(lo - self.base, max(self.upto, lo - 1) - self.base + 1)
        k = keep.stop - keep.start
        s = keep.start                          # (the states dropped: the move's shift)
        for B in (self.V9, self.V18):
            # in chunks of frequencies (128), and within a chunk in pieces of s states that do
            # not overlap their source: numpy copies an overlapping source whole before the move (35 MB a rank
            # for V18 on the paper's quarter case when it was one copy; half the time of a chunk's overlapping
            # copy)
            step = CHUNK_GROUPS
            for f0 in range(0, B.shape[0], step):
                blk = B[f0:f0 + step]
                for j in range(0, k if s else 0, s or 1):
                    blk[:, j:min(k, j + s)] = blk[:, j + s:min(k, j + s) + s]
                blk[:, k:] = 0.0
        self.base = lo

    def _catch_up(self, n, march):
        """Collective: the transforms of the states up to n (final) not yet kept."""
        PETSc = march.PETSc
        bufs = march.ubuf if self.side == "u" else march.pbuf
        for m in range(max(self.upto + 1, n - self.R + 1, 1), n + 1):
            with event("SSI_BEM_HistXform"):     # (the per-step transforms with their scatters, both ways)
                self.sc.scatter(bufs[march._slot(m)], self.seq, addv=PETSc.InsertMode.INSERT_VALUES)
                self._transform(self.seq.getArray(readonly=True), m)
                PETSc.Log.logFlops(self.fft.flops(27))
        self.upto = max(self.upto, n)

    def add(self, n, march, out_u):
        """Collective: out_u += sign (sum_{d=1..min(D, n-1)} K'_d v^{n-d} + sum_j A_j s_j^n) (this rank's
        rows; v the side's state, sign -1 for H on u, +1 for G on p; s_j^n = sum_m c_j(n, m) v^m the
        interpolated lags' weighted states). Time-blocked: at the first step of each block of b steps
        (n0 + 1, n0 a multiple of b, also after a restart) the terms of the states m <= n0 for all b steps
        at once (``lanes.history_lanes``, ``lanes.interp_lanes``: the kernels read once for the b steps); each
        step adds those of the block's states before it (m > n0)."""
        b = self.block
        n0 = b * ((n - 1) // b)
        if self._blk is None or self._blk[0] != n0:
            self._room(n0)
            self._catch_up(n0, march)
            ev = event("SSI_BEM_HistFFTBlock")
            ev.begin()
            self._blk = (n0, self._block_products(n0, march))
            ev.end()
        self._catch_up(n - 1, march)
        i = n - n0 - 1
        acc = self._blk[1][:, i:i + 1].copy()              # (groups, 1, 12, 2, FW): lanes
        self._step_products(n, n0, march, acc)
        self._apply(acc, out_u)

    def _block_products(self, n0, march):
        """(groups, b, 12, 2, FW) lanes: the terms of the states m <= n0 in the history sums of steps
        n0 + 1 .. n0 + b."""
        b, D, slab = self.block, self.D, self.f1 - self.f0
        flops = self._cflops() * 9 * (self.spec["n9"] + 2 * self.spec["n18"]) * slab     # a (d, step)
        acc = np.zeros((self.K9.shape[0], b, 12, 2, FW))
        if D:
            history_lanes(self.K9, self.K18, self.V9, self.V18, n0 + 1 - D - self.base, b, D, out=acc)
            march.PETSc.Log.logFlops(b * D * flops)
        if self.k:
            lo = n0 + 1 - self.R                         # the oldest state the block reads
            C = np.stack([self._weights(march, n0 + 1 + i, lo, n0) for i in range(b)])
            ev = event("SSI_BEM_HistInterp")
            ev.begin()
            acc += interp_lanes(self.A9, self.A18, self.V9, self.V18, C, lo - self.base, _low_rank, _spans(C),
                                march.PETSc.Log, slab=slab)
            ev.end()
        return acc

    def _step_products(self, n, n0, march, acc):
        """acc += the terms of the block's states n0 < m <= n - 1 in step n's history sum."""
        D = self.D
        k = min(n - n0 - 1, D)
        if k:                       # the block's states n - k .. n - 1 (d = k .. 1; k < n - n0 - 1 when D < b - 1)
            history_lanes(self.K9, self.K18, self.V9, self.V18, n - k - self.base, 1, k, out=acc, r0=D - k)
            march.PETSc.Log.logFlops(self._cflops() * k * 9 * (self.spec["n9"] + 2 * self.spec["n18"])
                                     * (self.f1 - self.f0))
        if self.k and n - 1 > n0:   # the interpolated lags' terms of the block's states (T_L within b steps)
            C = self._weights(march, n, n0 + 1, n - 1)[None]
            if C.any():
                acc += interp_lanes(self.A9, self.A18, self.V9, self.V18, C, n0 + 1 - self.base, _low_rank,
                                    _spans(C), march.PETSc.Log, slab=self.f1 - self.f0)

    def _cflops(self):
        """Flops of a kernel entry's product with a state's entry: 8 complex, 4 with a real kernel."""
        return 4.0 if self.real else 8.0

    def _weights(self, march, n, m_lo, m_hi):
        """(k, m_hi - m_lo + 1): the weight of state m_lo + i in the interpolated history s_j^n of step n
        (``Marcher._interp_coef``, the dense path's weights), zero for states outside 1..n-1."""
        C = np.zeros((self.k, m_hi - m_lo + 1))
        coef = march._interp_coef(n)
        if coef is not None:
            a, e = max(m_lo, 1), min(m_hi, n - 1)
            if e >= a:
                C[:, a - m_lo:e - m_lo + 1] = coef[a:e + 1].T
        return C

    def _apply(self, acc, out_u):
        """Collective: the summed slabs back by inverse FFTs over the ranks (``pfft``: the sums unpacked into
        its input, ``lanes.unpack_grid``), each node's value scattered from the rank whose grid rows hold it to
        the node's rank, added to out_u with the side's sign."""
        with event("SSI_BEM_HistXform"):
            unpack_grid(acc, self.spec["n9"], self.rot_out if self.real else _NO_ROT, self.fft.backward_inputs(12))
            self.fft.run_backward(12)                       # (into the array gvec wraps)
            self.osc.scatter(self.gvec, self.ovec)
            init().Log.logFlops(self.fft.flops(12))
        arr = out_u.getArray()
        vals = self.ovec.getArray(readonly=True)
        if self.spec["sign"] < 0:
            arr -= vals
        else:
            arr += vals


_NO_ROT = np.zeros((0, 0), np.complex128)


def _kernel_blocks(S):
    """(B9 (slab, 9, n9), B18 (slab, 18, n18)) complex: one lag's row blocks of K9 (z inputs, 9 rows)
    and K18 (x, y inputs, 18) from S (4, 9, m, slab), its kernel spectra (class, slot, pattern entry,
    frequency); m = 4 the H pattern (xz, yz, zx, zy: K9 columns (class, xz/yz), K18 rows (slot, zx/zy)
    columns class), m = 5 the G pattern (xx, xy, yx, yy, zz: K9 columns class (zz), K18 rows (slot, input
    component q) columns (class, output component p), entry 2 p + q)."""
    slab = S.shape[-1]
    if S.shape[2] == 4:
        return (S[:, :, 0:2, :].transpose(3, 1, 0, 2).reshape(slab, 9, 8),
                S[:, :, 2:4, :].transpose(3, 1, 2, 0).reshape(slab, 18, 4))
    G = S[:, :, 0:4, :].reshape(4, 9, 2, 2, slab)             # (class, slot, p, q, frequency)
    return S[:, :, 4, :].transpose(2, 1, 0), G.transpose(4, 1, 3, 0, 2).reshape(slab, 18, 8)


def _spans(C):
    """How ``interp_products`` forms the weighted states of C (b, k, ns): [(j0, j1, a, e)]: anchors j0..j1-1
    from states a..e-1. One product over all anchors and their common span when that span is at most
    twice their own spans' total (Chebyshev: every anchor weighs every state), else one per anchor
    (multi-linear: an anchor weighs the states of its two intervals only)."""
    nz = np.any(C != 0.0, axis=0)                       # (k, ns)
    own = []
    for j in range(C.shape[1]):
        i = np.flatnonzero(nz[j])
        if i.size:
            own.append((j, j + 1, int(i[0]), int(i[-1]) + 1))
    if not own:
        return []
    a, e = min(o[2] for o in own), max(o[3] for o in own)
    if C.shape[1] * (e - a) <= 2 * sum(o[3] - o[2] for o in own):
        return [(0, C.shape[1], a, e)]
    return own


def interp_products(A9, A18, V9, V18, C, r0, log=None, fchunk=64):
    """(The reference of ``lanes.interp_lanes``, which the store runs.) The interpolated lags' part of the
    history sum in Fourier space for b steps: per frequency the
    weighted states s_j = sum_m C[step, j, m] v^m of the kept transforms (states r0 + m of the
    frequency-major buffers (slab, W, c), double or single; real weights on the real and imaginary parts:
    per span of ``_spans`` and frequency one real matrix product of the weights with the span's states,
    read in place), then (b x 9k)(9k x n9) and (b x 18k)(18k x n18) products with the anchors' kernels: (slab, b, n9 + n18) complex, columns as
    ``history_products``. Frequencies in chunks so the weighted states stay small.

    A span's weights (b k rows, its states as columns) have a low numerical rank where one polynomial
    weighs them (Chebyshev: each row a polynomial of degree k - 1 in the state, apart from the few states
    at the ends of the steps' windows, which move with the step: rank about k + 2 (b + 2) of b k rows):
    there the product goes through the weights' singular vectors, C = (U s) W, W the rank's rows of V^T,
    the singular values below ``RANK_RTOL`` of the largest dropped (round-off: the dropped part of C is
    below that of its largest entry), when the rank is at most half the rows and the states: ``_low_rank``."""
    slab, n9, n18 = A9.shape[0], A9.shape[2], A18.shape[2]
    b, k, _ = C.shape
    out = np.zeros((slab, b, n9 + n18), np.complex128)
    spans = _spans(C)
    if not spans:
        return out
    facs = [_low_rank(C[:, j0:j1, a:e].reshape(-1, e - a)) for j0, j1, a, e in spans]
    for f0 in range(0, slab, fchunk):
        f1 = min(slab, f0 + fchunk)
        fc = f1 - f0
        S9 = np.zeros((fc, b, k, 9), np.complex128)
        S18 = np.zeros((fc, b, k, 18), np.complex128)
        for (j0, j1, a, e), (Cj, US, W) in zip(spans, facs):
            for V, S in ((V9, S9), (V18, S18)):
                c = V.shape[2]
                Vf = V[f0:f1, r0 + a:r0 + e].view(V.real.dtype)                   # (fc, e - a, 2 c): a view
                if W is None:
                    w = np.matmul(Cj, Vf)                                        # (fc, b (j1 - j0), 2 c)
                else:
                    w = np.matmul(US, np.matmul(W, Vf))
                S[:, :, j0:j1, :] = w.view(np.complex128).reshape(fc, b, j1 - j0, c)
        np.matmul(S9.reshape(fc, b, 9 * k), A9[f0:f1], out=out[f0:f1, :, :n9])
        np.matmul(S18.reshape(fc, b, 18 * k), A18[f0:f1], out=out[f0:f1, :, n9:])
    if log is not None:
        log.logFlops(interp_flops(slab, b, k, n9, n18, facs))
    return out


# the singular values of a span's weights kept for its low-rank product (``interp_products``): above this
# share of the largest
RANK_RTOL = 1e-15


_LOW_RANK_CACHE = {}         # the last few weights' factors: once the window is full every block's C is the same


def _low_rank(Cj):
    """(Cj, U s, W) with Cj = (U s) W to round-off (``RANK_RTOL``) when the rank r is at most half of both
    dimensions (U s: rows x r, W: r x states), else (Cj, None, None). The factors of the last few distinct
    weights are kept (keyed by their bytes): the blocks past the history's reach, and both sides, have the
    same weights."""
    m, n = Cj.shape
    if min(m, n) < 16 or not Cj.any():
        return Cj, None, None
    Cj = np.ascontiguousarray(Cj)
    key = (m, n, Cj.tobytes())
    got = _LOW_RANK_CACHE.get(key)
    if got is None:
        U, sv, Vt = np.linalg.svd(Cj, full_matrices=False)
        r = int(np.count_nonzero(sv > RANK_RTOL * sv[0]))
        got = (None, None) if 2 * r > min(m, n) else (np.ascontiguousarray(U[:, :r] * sv[:r]),
                                                      np.ascontiguousarray(Vt[:r]))
        if len(_LOW_RANK_CACHE) >= 8:
            _LOW_RANK_CACHE.pop(next(iter(_LOW_RANK_CACHE)))
        _LOW_RANK_CACHE[key] = got
    return (Cj,) + got


# the history products' window copies, per chunk of frequencies: at most about this many bytes (the
# largest transient of the time loop; 24 MB a rank on the paper's quarter case when the chunk was 64
# frequencies of a block, while a single step's products have windows of a few states only)
WINDOW_BYTES = 8e6


def history_products(K9, K18, V9, V18, p0, b, D, fchunk=None):
    """The history sum's products in Fourier space, per frequency f of a slab: for the b steps k of a
    block, sum_d K'_d v^{m}, m the state at row p0 + k + (D - d) of the time-ordered, frequency-major
    buffers (slab, W, c), as two matrix products per frequency, (b x 9D)-windows of V9 (z inputs) times K9
    (9D x n9) and (b x 18D) of V18 (x, y inputs) times K18 (18D x n18): (slab, b, n9 + n18) complex (H:
    columns (class, x or y) then z by class; G: z by class, then (class, x or y)). Step k's window is the
    contiguous run of states p0 + k .. p0 + k + D - 1 of a frequency: the windows are overlapping rows of
    one strided view, copied row by row (BLAS takes no overlapping rows): 9-24 % less time than
    gathering them from a time-major buffer (jobscripts/history_window_layout.py). The kept states double or single (the windows'
    copies in double); frequencies in chunks so the windows' copies stay small. The store itself takes these
    products in frequency lanes (``lanes.history_lanes``, compiled, no window copies); this ``matmul`` form is
    their reference (tests/bem/test_lanes.py) and the jobscripts' baseline."""
    from numpy.lib.stride_tricks import as_strided
    slab, n9, n18 = K9.shape[0], K9.shape[2], K18.shape[2]
    for V, c in ((V9, 9), (V18, 18)):       # (the strided windows read within each frequency's states only)
        if p0 < 0 or p0 + b - 1 + D > V.shape[1] or V.shape[2] != c or V.strides[2] != V.itemsize \
                or V.strides[1] != c * V.itemsize:
            raise ValueError(f"history_products: states {p0}..{p0 + b - 2 + D} of a buffer of {V.shape[1]} "
                             f"(shape {V.shape}, strides {V.strides}): out of range or not (slab, W, c) contiguous rows")
    out = np.empty((slab, b, n9 + n18), np.complex128)
    if fchunk is None:
        fchunk = max(1, int(WINDOW_BYTES // (b * 27 * D * 16)))
    for f0 in range(0, slab, fchunk):
        f1 = min(slab, f0 + fchunk)
        a9, a18 = (np.ascontiguousarray(as_strided(V[f0:f1, p0:], shape=(f1 - f0, b, c * D),
                                                   strides=V.strides, writeable=False), dtype=np.complex128)
                   for V, c in ((V9, 9), (V18, 18)))
        np.matmul(a9, K9[f0:f1], out=out[f0:f1, :, :n9])
        np.matmul(a18, K18[f0:f1], out=out[f0:f1, :, n9:])
    return out


def mirror_offsets(offsets):
    """The element's mirror symmetry (``_scatter_kernels``): (mirror (n_m, 2) the distinct offsets |o| in
    half element sizes, mirror_of (n,) each offset's row of it, flip (n,) 1 where o_x < 0 plus 2 where
    o_y < 0) of ``kernel_offsets``' rows."""
    o = np.asarray(offsets)[:, :2]
    mirror, mirror_of = np.unique(np.abs(o), axis=0, return_inverse=True)
    flip = (o[:, 0] < 0).astype(np.int64) + 2 * (o[:, 1] < 0).astype(np.int64)
    return mirror.astype(np.int64), np.asarray(mirror_of, np.int64).ravel(), flip


# the slot (SLOTS) of each slot mirrored: flip 0 none, 1 x -> -x, 2 y -> -y, 3 both
MIRROR_SLOTS = np.array([[SLOTS.index((sx * dx, sy * dy)) for dx, dy in SLOTS]
                         for sx, sy in ((1, 1), (-1, 1), (1, -1), (-1, -1))], np.int64)


def mirror_signs(p, q):
    """(4, m): the sign of each pattern entry (p[e], q[e]) of a 3 x 3 block under the mirrors of
    MIRROR_SLOTS: a reflection x -> -x turns a tensor's entry by -1 per x index (s_p s_q), y likewise; the
    surface's normal (z) stays."""
    p, q = np.asarray(p), np.asarray(q)
    out = np.ones((4, len(p)))
    for f, (fx, fy) in enumerate(((0, 0), (1, 0), (0, 1), (1, 1))):
        s = np.array([-1.0 if fx else 1.0, -1.0 if fy else 1.0, 1.0])
        out[f] = s[p] * s[q]
    return out


@njit(cache=True)
def _scatter_kernels(Kp, c_lo, rec, flip, meta, offP, P, t, kx, ky, code0, mslot, msign):
    """Kp[l - c_lo, t[o], mslot[flip[o], code0[a]], e, kx[o], ky[o]] = msign[flip[o], e] x the integrals of
    lag l of offset o's mirror offset |o|, record rec[o] (-1: integrated by another rank; pool layout of
    ``assemble._compact``: lag slot, local node a of the reference element, entry e of m = Kp.shape[3]),
    for the lags of the chunk (slot code0[a]: the node's position).

    The element is symmetric about its centre lines and the surface is flat: with the reflection
    x -> -x, the integral of the node at slot a at the offset o is the mirrored node's at the mirrored
    offset, each entry (p, q) times s_p s_q (-1 per x index): K_a(Rx o) = S_x K_{Rx a}(o), and likewise in
    y. The Gauss points, the subdivisions and the lags' windows are symmetric too, so one integral at |o|
    serves the four offsets (+-o_x, +-o_y): a quarter of the integrals, each the same to round-off
    (tests/bem/test_toeplitz_mirror.py)."""
    nl_c = Kp.shape[0]
    ns = Kp.shape[2]                # (the first ns slots: 5 for real kernels, whose mirrors 5..8 are not needed)
    m = Kp.shape[3]
    for o in range(rec.shape[0]):
        r = rec[o]
        if r < 0:
            continue
        f = flip[o]
        lo, hi = meta[r, 0], meta[r, 1]
        base = offP[r]
        for l in range(max(lo, c_lo), min(hi, c_lo + nl_c - 1) + 1):
            s = base + (l - lo) * 9 * m
            for a in range(9):
                sl = mslot[f, code0[a]]
                if sl >= ns:
                    continue
                for e in range(m):
                    Kp[l - c_lo, t[o], sl, e, kx[o], ky[o]] = msign[f, e] * P[s + m * a + e]
