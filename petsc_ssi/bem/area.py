"""The soil's side of an area load (``sources.area``): its lag vectors g_l on the rows a rank owns, and
their terms in each step's right-hand side.

Integration. The rectangle is tiled into pieces no larger than the smallest element that reaches it (a piece is
a flat nine-node element of the plane z = 0, nodes ordered as the mesh's, normal +z). Each (collocation
point, piece) pair is integrated as the assembly integrates a pair (``assemble._pair_window``: the lags
its wave window touches, the near-field subdivisions; ``assemble.integrate_records``): a point at one of
the piece's nine nodes is that node's singular pair. A point inside a piece (or on its edge) that is not
one of its nodes splits the piece, for that point only, into two or four pieces with the point at their
common corner, each a singular pair. So a rectangle that is one mesh cell is integrated exactly as that
cell (the cell's ``SurfaceTraction`` gives the same vectors to round-off), and any other rectangle as
if the mesh had a cell there.

With symmetry planes the rectangle's part in the meshed region and its mirror images are integrated, each
with its mirrored traction S f (``sources.area.AreaTraction.images``), and summed.

Lags: 1 .. the last the run reaches (n_steps + 1) or the rectangle's causal limit, whichever is
smaller; g_l = sum over the pieces and their nine nodes of the U^l blocks times f.

Right-hand side (``AreaHistory.add``, called by ``Marcher.begin_step``): the load enters the step
equations E_n exactly as a known traction on a cell does (``march``'s module docstring): plain, g_1 a_n
+ sum_{j>=2} g_j a_{n-j+1}; stabilised, (4 g_1 + g_2) a_n + sum_{j>=2} g_j q_j(a). One product a step
of the (rows x lags) block with the weights of the lags.
"""
import math
import time

import numpy as np
from numba import njit

from ..petsc import SSIError, printf
from .assemble import _pair_window, integrate_records, plane, SING_TOL
from .quadrature import _NXI, _NET
from .windows import bounding_spheres

CHUNK_BYTES = 64e6      # the integrals of at most this many bytes at a time per rank


def piece(x0, x1, y0, y1, z=0.0):
    """The nine nodes (9, 3) of the rectangle as a nine-node element (the mesh's node order, normal +z)."""
    X = np.empty((9, 3))
    X[:, 0] = 0.5 * (x0 + x1) + 0.5 * (x1 - x0) * _NXI
    X[:, 1] = 0.5 * (y0 + y1) + 0.5 * (y1 - y0) * _NET
    X[:, 2] = z
    return X


def tiles(rect, hmax):
    """The rectangle tiled into equal pieces no longer than ``hmax`` on a side: (k, 4) rows (x0, x1, y0, y1)."""
    x0, x1, y0, y1 = rect
    nx, ny = (max(1, int(math.ceil((b - a) / hmax * (1 - 1e-12)))) for a, b in ((x0, x1), (y0, y1)))
    xs, ys = np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1)
    return np.array([(xs[i], xs[i + 1], ys[j], ys[j + 1]) for i in range(nx) for j in range(ny)])


def split(r, p, eps=0.0):
    """The pieces of rectangle r = (x0, x1, y0, y1) cut at the point p's lines x = p_x, y = p_y (those
    inside it by more than ``eps``: a point that close to an edge is on it, no sliver is cut): 1, 2 or 4
    rectangles with p at (within eps of) a corner of each."""
    x0, x1, y0, y1 = r
    xs = [x0] + ([p[0]] if x0 + eps < p[0] < x1 - eps else []) + [x1]
    ys = [y0] + ([p[1]] if y0 + eps < p[1] < y1 - eps else []) + [y1]
    return [(xs[i], xs[i + 1], ys[j], ys[j + 1]) for i in range(len(xs) - 1) for j in range(len(ys) - 1)]


@njit(cache=True)
def _windows(pts, VX, Vc, VR, Vh, reach, cp, cs, dt, L, tol, ns_base, ns_max, near):
    """The (point, piece) pairs that reach a lag, compacted (two passes: no points x pieces array): (meta
    (m, 6) of ``integrate_records``: lo, hi, sing, ns, want_u = 2 (G alone), piece; point (m,); inside (q, 2): the
    (point, piece) pairs whose point lies in the piece's closed rectangle without being one of its nodes,
    to be cut, not in meta)."""
    n, k = pts.shape[0], VX.shape[0]
    counts = np.zeros(2, np.int64)
    for fill in range(2):
        if fill:
            meta = np.zeros((counts[0], 6), np.int64)
            point = np.zeros(counts[0], np.int64)
            inside = np.zeros((counts[1], 2), np.int64)
            counts[:] = 0
        for i in range(n):
            for e in range(k):
                lo, hi, sing, ns = _pair_window(pts[i], VX[e], Vc[e], VR[e], Vh[e], reach, cp, cs, dt, L,
                                                np.int64(1), 0.0, tol, ns_base, ns_max, near)   # (lag_lo not literal)
                eps = tol * Vh[e]
                if sing < 0 and VX[e, 0, 0] - eps <= pts[i, 0] <= VX[e, 2, 0] + eps and \
                        VX[e, 0, 1] - eps <= pts[i, 1] <= VX[e, 2, 1] + eps:
                    if fill:
                        inside[counts[1], 0] = i
                        inside[counts[1], 1] = e
                    counts[1] += 1
                elif hi >= lo:
                    if fill:
                        r = counts[0]
                        meta[r, 0] = lo
                        meta[r, 1] = hi
                        meta[r, 2] = sing
                        meta[r, 3] = ns
                        meta[r, 4] = 2
                        meta[r, 5] = e
                        point[r] = i
                    counts[0] += 1
    return meta, point, inside


@njit(cache=True)
def _reduce(g, rows, meta, offU, U, f, gp, gq):
    """g[3 rows[r] + p, l - 1] += sum_a U(l, a, p, q) f_q over the records r (the pool's compacted pattern
    entries (gp, gq): ``assemble._compact``'s layout)."""
    m = gp.shape[0]
    for r in range(meta.shape[0]):
        lo, hi = meta[r, 0], meta[r, 1]
        k = offU[r]
        for li in range(hi - lo + 1):
            for a in range(9):
                for j in range(m):
                    g[3 * rows[r] + gp[j], lo + li - 1] += U[k] * f[gq[j]]
                    k += 1


def tile_size(ls, rect):
    """The size of the rectangle's pieces: the smallest element whose bounding sphere reaches the rectangle
    (its cells' size on a graded mesh, not the mesh's largest), the largest element if none does."""
    x0, x1, y0, y1 = rect
    c = ls.Vc
    dx = np.maximum(np.maximum(x0 - c[:, 0], c[:, 0] - x1), 0.0)
    dy = np.maximum(np.maximum(y0 - c[:, 1], c[:, 1] - y1), 0.0)
    near = np.hypot(dx, dy) <= ls.VR
    return float(ls.Vh[near].min()) if np.any(near) else float(ls.Vh.max())


def _records(pts, rect, hmax, ls, L):
    """(meta, points, pieces VX, bad) of every (owned point, piece) pair that reaches a lag, the pieces that
    hold a point (not at one of their nodes) split for that point; ``bad``: a point whose cut pieces do not
    have it as a node (0 or 1, for a collective error)."""
    o, mat, dt = ls.opts, ls.mat, ls.dt
    base = [piece(*t) for t in tiles(rect, hmax)]
    VX = np.array(base)
    c, R, h = bounding_spheres(VX)
    reach = mat.cp * dt * L + 1e-9
    args = (SING_TOL, int(o["subdivisions"]), int(o["max_subdivisions"]), float(o["near_factor"]))
    meta, point, inside = _windows(pts, VX, c, R, h, reach, mat.cp, mat.cs, dt, L, *args)
    extra_meta, extra_pt, extra_X = [], [], []
    bad = 0
    for i, e in inside:                          # (the few points on the rectangle)
        x0, x1, y0, y1 = VX[e, 0, 0], VX[e, 2, 0], VX[e, 0, 1], VX[e, 2, 1]
        eps = 0.25 * SING_TOL * min(x1 - x0, y1 - y0)
        subs = np.array([piece(*s) for s in split((x0, x1, y0, y1), pts[i], eps)])
        sc, sR, sh = bounding_spheres(subs)
        m, _, cut = _windows(pts[i:i + 1], subs, sc, sR, sh, reach, mat.cp, mat.cs, dt, L, *args)
        bad = max(bad, int(len(cut) > 0 or np.any(m[:, 2] < 0)))
        m[:, 5] += len(VX) + len(extra_X)
        extra_meta.append(m)
        extra_pt += [i] * len(m)
        extra_X += list(subs)
    if extra_meta:
        meta = np.concatenate([meta] + extra_meta)
        point = np.concatenate([point, np.array(extra_pt, np.int64)])
        VX = np.concatenate([VX, np.array(extra_X)])
    return meta, point, VX, bad


def lag_vectors(ls, src, n_steps):
    """Collective: (g (3 owned rows, lags), seconds): the area load ``src``'s lag vectors on this rank's
    rows, summed over its rectangle's symmetry images (``src.images``; the rectangle alone without planes).
    Every rank agrees on the lag count (the largest any row reaches)."""
    t0 = time.perf_counter()
    parts = [_lag_vectors(ls, rect, f, n_steps) for rect, f in src.images(ls.planes)]
    g = np.zeros((parts[0].shape[0], max(p.shape[1] for p in parts)))
    for p in parts:
        g[:, :p.shape[1]] += p
    return g, time.perf_counter() - t0


def _lag_vectors(ls, rect, f, n_steps):
    """Collective: the lag vectors (3 owned rows, lags) of the traction f [Pa] on ``rect``."""
    from mpi4py import MPI
    mpi = ls.comm.tompi4py()
    o, mat = ls.opts, ls.mat
    pts = np.ascontiguousarray(ls.mesh.nodes[ls.rows], float)
    L = int(n_steps) + 1
    meta, point, VX, bad = _records(pts, rect, tile_size(ls, rect), ls, L)
    if mpi.allreduce(bad, op=MPI.MAX):          # (every rank: no hang)
        raise SSIError(f"-ssi_load_area: a collocation point on the rectangle {rect} is not a node of the pieces cut "
                       "at it; report this with the mesh")
    Ls = mpi.allreduce(int(meta[:, 1].max()) if len(meta) else 0, op=MPI.MAX)
    g = np.zeros((3 * len(pts), max(Ls, 1)))
    gq_, gw_ = np.polynomial.legendre.leggauss(o["gauss"])
    gr, gwr = np.polynomial.legendre.leggauss(o["singular_order"])
    pat = ls.pattern()
    geo = plane(ls.in_plane, VX, int(o["subdivisions"]), gq_, gw_, int(o["max_subdivisions"]))
    dropped = np.zeros(2)
    per = 8.0 * 9 * len(pat[2]) * np.maximum(meta[:, 1] - meta[:, 0] + 1, 0)
    ends = np.searchsorted(np.cumsum(per), np.arange(1, int(per.sum() // CHUNK_BYTES) + 2) * CHUNK_BYTES)
    start = 0
    for end in np.unique(np.append(ends, len(meta))):
        if end <= start:
            continue
        mm = np.ascontiguousarray(meta[start:end])
        _, _, offU, U, _ = integrate_records(mm, pts[point[start:end]], VX, Ls, ls.dt, mat.cp, mat.cs, mat.rho,
                                             mat.nu, gq_, gw_, gr, gwr, 0.0, float(ls.Vh.min()), pat, dropped,
                                             int(o["subdivisions"]), geo)
        _reduce(g, point[start:end], mm, offU, U, np.asarray(f, float), pat[2], pat[3])
        start = end
    lost = mpi.allreduce(float(dropped.max()), op=MPI.MAX)
    if lost > 1e-12 * max(mpi.allreduce(float(np.abs(g).max()) if g.size else 0.0, op=MPI.MAX), 1e-300):
        raise SSIError(f"-ssi_load_area: a block entry outside the surface's pattern is {lost:.3g}, not 0; "
                       "report this with the mesh")
    return g


class AreaHistory:
    """The area loads' terms of each step's right-hand side (module docstring): ``add(n, march, b)``."""

    def __init__(self, sources, gs, dt, zero_local, n_steps):
        self.sources, self.dt, self.gs = sources, dt, gs
        self.zero_local = zero_local
        # a[m]: each source's step mean of step m (a[0] = 0), once for the run
        self.a = [np.array([0.0] + [s.step_mean(m, dt) for m in range(1, n_steps + 2)]) for s in sources]

    @staticmethod
    def weights(a, n, march, Ls):
        """w[j - 1]: the weight of g_j in step n's right-hand side, a[m] the step means (the known traction's
        lags 1, 2 with the step matrix's coefficients, ``Marcher.add_known``; the history's q_j(a) of j >= 2,
        ``Marcher._terms``: states 1..n-1)."""
        w = np.zeros(Ls)
        for lag, c in march.coefficients():
            if lag <= Ls:
                w[lag - 1] += c * a[n]
        j = np.arange(2, min(Ls, n + 1) + 1)
        offs = ((2, 1.0), (1, 2.0), (0, 1.0)) if march.scheme == "stabilized" else ((1, 1.0),)
        for off, c in offs:
            m = n - j + off
            ok = (m >= 1) & (m <= n - 1)
            w[j[ok] - 1] += c * a[m[ok]]
        return w

    def add(self, n, march, b):
        """b += the area loads' terms of step n (b: this rank's rows)."""
        arr = b.getArray()
        for a, g in zip(self.a, self.gs):
            if g.shape[0]:
                arr += g @ self.weights(a, n, march, g.shape[1])
        if self.zero_local.size:
            arr[self.zero_local] = 0.0


def build(ls, sources, n_steps, zero_local):
    """Collective: the AreaHistory of ``sources`` (area loads) on this rank's rows, with one log line each
    (monitor or not: its memory and time)."""
    from mpi4py import MPI
    mpi = ls.comm.tompi4py()
    gs = []
    for src in sources:
        g, sec = lag_vectors(ls, src, n_steps)
        gb = mpi.allreduce(8.0 * g.size, op=MPI.SUM) / 1e9
        printf(f"[ssi] {src.name}: its lag vectors integrated over the rectangle in {sec:.2f} s ({g.shape[1]} lags, "
            f"{gb:.3g} GB over the ranks)")
        gs.append(g)
    return AreaHistory(sources, gs, ls.dt, zero_local, n_steps)
