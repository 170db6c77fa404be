r"""The interface columns Z = A^{-1} H_s E_I of the coupled step on a region around the interface
(``-ssi_interface_columns``; issue 41's building on a large uniform grid).

A is the soil's step matrix (lags 1-2: a node couples only to the nodes of the elements a wave reaches
within a step or two, at most the *reach* r = c_p t + the largest element diameter apart,
``bem.toeplitz.geometric_reach``). Its inverse decays geometrically away from the diagonal: on the paper's building on
the uniform 72 m grid (1.2 m cells, dt = 5 ms, 44 649 DOFs, reach 3.78 m) the truncation residual below
falls by about four orders of magnitude per reach of margin (``jobscripts/columns_margin.sh``; about three
and a half on a quarter model with symmetry planes). So the columns' rows beyond a margin of a few reaches
are zero to round-off, and the kept rows are the solution of the same equations restricted to the region
Omega of the DOFs within the margin of an interface node:

    A_{Omega Omega} Z_Omega = (H_s E_I)_Omega,     Z = Z_Omega on Omega, 0 elsewhere,

a factorisation and 3 n_I solves of a matrix a fraction of A's size instead of 3 n_I solves with A's
factors (and each step's correction x -= Z du reads Z_Omega's rows only). The truncation is checked,
not assumed: the residual A Z - H_s E_I of the region's solution is nonzero only in the rows just outside
Omega that couple into it (A_{ring Omega} Z_Omega), computed for every column; where its largest value
exceeds ``TOL`` times the column's right-hand side, the margin is doubled, and where Omega would then hold
most of the grid the columns are solved with A's own factors (``full``), as before. The step equations
themselves are unchanged (the run's residual check, ``bem_residual``, measures them every step).

Where the region's matrix splits into mirror-symmetric blocks (``bem.mirror``: A_{Omega Omega} commutes with
the reflections R_g, signed permutations of the region's DOFs), so do the columns: the right-hand side of
interface DOF (g(k), c) is s_g(c) R_g times that of (k, c), hence Z e_(g(k), c) = s_g(c) R_g Z e_(k, c). Only the
columns of each orbit's representative node are solved (390 of the uniform 72 m building's 1425), the others
are mirrored from them; each image's right-hand side is checked against its representative's mirrored first
(``MIRROR_TOL``, every column solved otherwise), and each image's truncation residual is computed as any
column's. The steps keep the representatives' columns alone and form Z d from them (``MirroredZ``: one pass over
their rows for the mirror group's right-hand sides, then the signed permutations), a share of the bytes each
step's product read before (390 of 1425 columns on that building).
"""
import numpy as np
from numba import njit

from ..petsc import init, printf, solve_columns, set_default_options, soil_solver_defaults, mumps_failure
from ..bem.toeplitz import geometric_reach

# the largest residual of the region's columns, over the column's right-hand side (both in the
# infinity norm), that keeps the region: round-off of the step equations' own size
TOL = 1e-14
# auto: the region when it holds at most this share of the soil's DOFs (the full solve otherwise)
AUTO_SHARE = 0.6
# the region's MUMPS LU: percentage of workspace beyond the analysis' estimate (MUMPS's default 20)
ICNTL14 = 60
# a mirror image's right-hand side against its representative's mirrored (``RegionColumns._images_hold``), over
# its largest entry: the step matrix's own commutation bound (``bem.mirror.TOL``)
MIRROR_TOL = 1e-12


def region_nodes(X, nodes_I, margin):
    """Boolean mask of the nodes of X within ``margin`` [m] of an interface node (3-D distance)."""
    from scipy.spatial import cKDTree
    d, _ = cKDTree(X[nodes_I]).query(X, k=1)
    return d <= margin


class RegionColumns:
    """Collective: Z's columns ``cols`` (of the 3 n_I interface DOFs) on the region within ``margin`` [m]
    of the interface nodes. ``rhs(i0, i1)``: the right-hand sides i0..i1-1 of ``cols`` as the rank's full
    local rows (local rows, i1 - i0). After ``solve()``: ``rows`` (the rank's local row indices of the
    region, ascending), ``Z`` (len(rows), 3 n_I) and ``residual`` (the largest ring residual over its
    column's right-hand side); ``ok`` whether it is within ``TOL`` and every right-hand side lies in the
    region; ``n_solved`` the columns solved (the others mirror images: module docstring)."""

    def __init__(self, march, X, nodes_I, margin, log=printf):
        PETSc = init()
        self.PETSc, self.march, self.comm = PETSc, march, march.comm
        self.orbits = None          # after ``solve`` with mirror images: (rep columns, their images, {g: R_g})
        A = march.A
        r0, r1 = A.getOwnershipRange()
        self.inside_nodes = region_nodes(X, nodes_I, margin)
        self.nodes = np.flatnonzero(self.inside_nodes)          # the region's nodes, and each node's index in them
        self.where = -np.ones(len(X), np.int64)
        self.where[self.nodes] = np.arange(self.nodes.size)
        inside = np.repeat(self.inside_nodes, 3)
        self.X = X
        self.nodes_I = np.asarray(nodes_I, np.int64)
        self.margin = margin
        self.keep = inside[r0:r1]
        self.rows = np.flatnonzero(self.keep)
        mpi = self.comm.tompi4py()
        self.n_region = int(mpi.allreduce(int(self.rows.size)))
        self.n_all = A.getSize()[0]
        gl = (r0 + self.rows).astype(PETSc.IntType)
        self.is_r = PETSc.IS().createGeneral(gl, comm=self.comm)
        # the ring: rows outside the region that couple into it (their residual is the truncation's)
        ip, jj, _ = A.getValuesCSR()
        ip = np.asarray(ip, np.int64)
        row_e = np.repeat(np.arange(r1 - r0), np.diff(ip))
        per_row = np.bincount(row_e[inside[np.asarray(jj, np.int64)]], minlength=r1 - r0)
        ring = np.flatnonzero((per_row > 0) & ~self.keep)
        self.is_ring = PETSc.IS().createGeneral((r0 + ring).astype(PETSc.IntType), comm=self.comm)
        self.n_ring = int(mpi.allreduce(int(ring.size)))
        self.log = log

    def solve(self, cols, n_cols, rhs):
        PETSc, A = self.PETSc, self.march.A
        AR = A.createSubMatrix(self.is_r, self.is_r)
        AQ = A.createSubMatrix(self.is_ring, self.is_r)
        ksp = PETSc.KSP().create(comm=self.comm)
        ksp.setOptionsPrefix("ssi_bem_columns_")
        defaults = soil_solver_defaults(self.comm)
        if defaults.get("pc_factor_mat_solver_type") == "mumps":
            # MUMPS's workspace relaxation: a region's submatrix pivots more than A (its cut rows), and
            # its LU ran out of the default 20 % (INFOG(1) = -9) at 3.5 reaches on the uniform 72 m building
            defaults["mat_mumps_icntl_14"] = str(ICNTL14)
        set_default_options("ssi_bem_columns_", defaults, self.log)
        mb = self._mirror(AR)
        ksp.setOperators(AR if mb is None else mb.Ap)
        ksp.setFromOptions()
        ksp.setUp()
        self.failed = mumps_failure(ksp)
        if mb is not None and not self.failed and not self._blocks_solve(ksp, AR, mb):
            mb.destroy()                        # (the blocks' solve off AR's: the region's matrix as it is)
            mb = None
            ksp.destroy()
            ksp = PETSc.KSP().create(comm=self.comm)
            ksp.setOptionsPrefix("ssi_bem_columns_")
            ksp.setOperators(AR)
            ksp.setFromOptions()
            ksp.setUp()
            self.failed = mumps_failure(ksp)
        self.mirrored = mb is not None
        if self.failed:                         # (every rank: INFOG is global)
            self.ok, self.residual, self.rhs_outside, self.Z = False, float("nan"), False, None
            for o in (ksp, AR, AQ) + (() if mb is None else (mb,)):
                o.destroy()
            self.destroy()
            return self
        tmpl = AR.createVecRight()
        rq = AQ.createVecLeft()
        Z = np.zeros((self.rows.size, n_cols))
        bmax = np.zeros(len(cols))
        rmax = np.zeros(len(cols))
        outside = [False]

        def block(i0, i1):
            full = rhs(i0, i1)
            if full.shape[0] and np.any(full[~self.keep] != 0.0):
                outside[0] = True
            blk = np.ascontiguousarray(full[self.rows])
            if blk.size:
                bmax[i0:i1] = np.abs(blk).max(axis=0)
            return blk

        def fill(i, b):                         # (not reached: ``block`` always gives the columns)
            b.getArray()[:] = block(i, i + 1)[:, 0]

        def take(i, z):
            Z[:, cols[i]] = z.getArray(readonly=True)
            AQ.mult(z, rq)
            a = rq.getArray(readonly=True)
            rmax[i] = np.abs(a).max() if a.size else 0.0

        orb = None if mb is None else self._orbits(mb.refl, cols, AR)
        if orb is not None:
            orb = self._images_hold(orb, cols, block, tmpl, bmax)
        if orb is None:
            solve_columns(ksp, tmpl, len(cols), fill, take, block=block, Q=None if mb is None else mb.Q)
            self.n_solved = len(cols)
        else:                                   # the representatives solved, each image R_g z s_g(c) from them
            reps, images, R, Brep = orb
            orb = None
            y = tmpl.duplicate()

            def take_rep(r, z):
                take(reps[r], z)
                for g, i, sgn in images[r]:
                    R[g].mult(z, y)
                    y.scale(sgn)
                    take(i, y)
            solve_columns(ksp, tmpl, len(reps), None, take_rep, block=lambda a, b: Brep[:, a:b], Q=mb.Q)
            self.n_solved = len(reps)
            y.destroy()
            del Brep
            self.orbits = (np.asarray(cols, np.int64)[reps],
                           [[(g, int(cols[i]), sgn) for g, i, sgn in lst] for lst in images], R)
        from mpi4py import MPI
        mpi = self.comm.tompi4py()
        mpi.Allreduce(MPI.IN_PLACE, bmax, op=MPI.MAX)
        mpi.Allreduce(MPI.IN_PLACE, rmax, op=MPI.MAX)
        self.rhs_outside = bool(mpi.allreduce(outside[0], op=MPI.LOR))
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.where(bmax > 0, rmax / np.where(bmax > 0, bmax, 1.0), rmax)
        self.residual = float(rel.max()) if rel.size else 0.0
        if not np.all(np.isfinite(rmax)):     # (a NaN is not a residual within the bound; MAX may drop it)
            self.residual = float("nan")
        self.ok = (not self.rhs_outside) and bool(np.isfinite(self.residual)) and self.residual <= TOL
        self.Z = Z
        for o in (ksp, AR, AQ, tmpl, rq) + (() if mb is None else (mb,)):
            o.destroy()
        self.destroy()
        return self

    def _orbits(self, refl, cols, AR):
        """The interface columns' orbits under the region's mirror group (``bem.mirror.group`` of ``refl``):
        (reps, images, R) with ``reps`` the positions in ``cols`` of the columns to solve (the orbit's first
        interface node in ``nodes_I``, each component), ``images[r]`` the [(g, position, sign)] of the columns rep r gives
        (Z e_(g(k), c) = s_g(c) R_g Z e_(k, c): A and H_s commute with R_g, the signed permutation of the
        region's DOFs, ``bem.mirror.signed_permutation``) and ``R`` {g: R_g}; None where an interface node's
        mirror image is not an interface node or a column's image is not among ``cols``."""
        from ..bem.mirror import group, signed_permutation
        maps, signs, _ = group(refl)
        got = orbit_representatives(maps, self.nodes_I, self.where)
        if got is None:
            return None
        rep_nodes, img = got                    # (img[g, k]: the interface node g(k))
        is_rep = np.zeros(self.nodes_I.size, bool)
        is_rep[rep_nodes] = True
        cols = np.asarray(cols, np.int64)
        pos = -np.ones(3 * self.nodes_I.size, np.int64)
        pos[cols] = np.arange(cols.size)
        k, c = cols // 3, cols % 3
        reps = np.flatnonzero(is_rep[k])
        done = np.zeros(cols.size, bool)
        done[reps] = True
        images = []
        for r in reps:
            lst = []
            for g in range(1, len(maps)):
                i = int(pos[3 * img[g, k[r]] + c[r]])
                if i < 0:
                    return None
                if not done[i]:
                    done[i] = True
                    lst.append((g, i, float(signs[g, c[r]])))
            images.append(lst)
        if not done.all():                      # (a column among ``cols`` whose representative's is not)
            return None
        r0, r1 = AR.getOwnershipRange()
        R = {g: signed_permutation(self.PETSc, self.comm, maps[g], signs[g], r0, r1) for g in range(1, len(maps))}
        self.planes = [(int(axis), float(c)) for axis, c, _ in refl]
        return reps, images, R

    def _images_hold(self, orb, cols, rhs, tmpl, bmax):
        """Collective: (reps, images, R, Brep) with Brep the representatives' right-hand sides on the region's
        rows, when each image column's right-hand side is its representative's mirrored, s_g(c) R_g b_r, to
        ``MIRROR_TOL`` of its own size (``bmax``, this rank's largest entry of each, which ``rhs`` records); else
        None (every column solved, its right-hand sides read again), said in one line. Every column's right-hand
        side is read (``rhs`` in chunks: the same calls as the full solve, which record each column's size and
        whether it reaches outside) and held for the check, a transient the size of Z's rows; only the
        representatives' stay for the solve."""
        from mpi4py import MPI
        reps, images, R = orb
        n = len(cols)
        B = np.empty((self.rows.size, n))
        for i0 in range(0, n, 256):
            i1 = min(n, i0 + 256)
            B[:, i0:i1] = rhs(i0, i1)
        diff = np.zeros(n)
        size = bmax.copy()
        vb, vy = tmpl.duplicate(), tmpl.duplicate()
        for r, lst in zip(reps, images):
            vb.getArray()[:] = B[:, r]
            for g, i, sgn in lst:
                R[g].mult(vb, vy)
                d = B[:, i] - sgn * vy.getArray(readonly=True)
                diff[i] = np.abs(d).max() if d.size else 0.0
        vb.destroy()
        vy.destroy()
        mpi = self.comm.tompi4py()
        mpi.Allreduce(MPI.IN_PLACE, diff, op=MPI.MAX)
        mpi.Allreduce(MPI.IN_PLACE, size, op=MPI.MAX)
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.where(size > 0, diff / np.where(size > 0, size, 1.0), diff)
        worst = float(rel.max()) if rel.size else 0.0
        if not worst <= MIRROR_TOL:
            self.log(f"[ssi] interface columns: an image column's right-hand side differs from its mirrored "
                     f"representative's by {worst:.3g} > {MIRROR_TOL:g} of its size; every column solved")
            for o in R.values():
                o.destroy()
            return None
        Brep = np.ascontiguousarray(B[:, reps])
        del B
        return reps, images, R, Brep

    def _mirror(self, AR):
        """Collective: the region's matrix in mirror-symmetric blocks (``bem.mirror``) when the step matrix's LU
        is (the region around a mirror-symmetric interface is mirror-symmetric too), else None. The columns
        are checked as always (their ring residual), and the blocks' commutation before."""
        m = self.march
        if getattr(m, "mirror", None) is None:
            return None
        from ..bem.mirror import MirrorBlocks
        nodes, where = self.nodes, self.where
        reg = m.reg
        tn = where[np.asarray(reg.tnode)[reg.n_load:]] if reg.n_t else np.zeros(0, np.int64)
        mb = MirrorBlocks(self.PETSc, self.comm, AR, self.X[nodes], m.pres[nodes], tn[tn >= 0])
        if mb.why:
            mb.destroy()
            return None
        return mb

    def _blocks_solve(self, ksp, AR, mb):
        """Collective: whether the region's blocks solve AR x = b on a fixed right-hand side (the same as the
        step matrix's test, ``march._test_residual``) to the step matrix's test bound, ``march.BLR_TOL``."""
        from ..bem.march import BLR_TOL
        from ..bem.mirror import solve_residual
        res = solve_residual(AR, lambda b, x: mb.solve(ksp, b, x))
        if not res <= BLR_TOL:
            self.log(f"[ssi] interface columns: the region's mirror-symmetric blocks left a residual {res:.3g} > "
                     f"{BLR_TOL:g} on a test right-hand side; its matrix as it is instead")
            return False
        return True

    def destroy(self):
        for o in (self.is_r, self.is_ring):
            o.destroy()


def region_columns(cfg, march, prob, nodes_I, cols, n_cols, rhs, log=printf):
    """Collective: Z's columns on a region around the interface when ``-ssi_interface_columns`` (auto or
    region) allows it: (rows, Z, line, mz) with ``line`` the log's account and ``mz`` a ``MirroredZ`` where
    the columns are mirror images of their orbits' representatives' (else None), or None (the caller solves
    with A's factors: full, a region holding most of the grid, or no region within the margins tried)."""
    mode = str(cfg.get("interface_columns") or "auto").lower()
    if mode == "full":
        return None
    X = prob.mesh.nodes
    reach = geometric_reach(cfg, prob)
    margin = float(cfg.get("interface_columns_margin") or 4.0) * reach
    share_max = 1.0 if mode == "region" else AUTO_SHARE
    tried = []
    while True:
        reg = RegionColumns(march, X, nodes_I, margin, log)
        share = reg.n_region / max(reg.n_all, 1)
        if share > share_max or reg.n_region == reg.n_all:     # (the whole grid: A's own factors serve)
            reg.destroy()
            why = (f"the region within {margin:.3g} m of the interface holds {100 * share:.0f} % of the soil's "
                   f"DOFs")
            printf("[ssi] interface columns: with the step matrix's factors (" + why
                   + (f"; {', '.join(tried)}" if tried else "") + "; -ssi_interface_columns)")
            return None
        reg.solve(cols, n_cols, rhs)
        if reg.failed:
            printf(f"[ssi] interface columns: with the step matrix's factors (the region's own LU within {margin:.3g} m "
                   f"of the interface: {reg.failed}; -ssi_bem_columns_mat_mumps_icntl_14 more workspace, "
                   "-ssi_interface_columns)")
            return None
        if reg.ok:
            line = (f"[ssi] interface columns: on the {reg.n_region} soil DOFs within {margin:.3g} m of the "
                    f"interface ({100 * share:.0f} % of {reg.n_all}; margin {margin / reach:.3g} x the step "
                    f"matrix's reach {reach:.3g} m, c_p t + the largest element), their own LU"
                    f"{' (mirror-symmetric blocks, as the step matrix)' if reg.mirrored else ''}"
                    f"{f', {reg.n_solved} of {len(cols)} columns solved, the others their mirror images' if reg.n_solved < len(cols) else ''}"
                    f"; truncation residual {reg.residual:.2e} of "
                    f"the right-hand sides (<= {TOL:g}; -ssi_interface_columns)"
                    + (f"; tried first: {', '.join(tried)}" if tried else ""))
            mz = None
            if reg.orbits is not None:
                mz = MirroredZ(reg.Z, *reg.orbits)
                mz.planes = reg.planes
                reg.orbits = None
            return reg.rows, reg.Z, line, mz
        if reg.orbits is not None:
            for R in reg.orbits[2].values():
                R.destroy()
            reg.orbits = None
        tried.append(f"{margin:.3g} m: residual {reg.residual:.2e}"
                     + (", a right-hand side outside" if reg.rhs_outside else ""))
        margin *= 2.0


@njit(cache=True, fastmath={"reassoc", "contract"})
def _rows4(Z, D, out):
    """out[i, g] = sum_j Z[i, j] D[g, j], g = 0..3 (D (4, m): a mirror group's order is at most 4, rows past it
    zero): one pass over Z's rows for the four right-hand sides; the sums reassociated (vectorised), so they differ
    from another order's at round-off, the same on every rank for a row. `python jobscripts/mirrored_z_rate.py` (the
    uniform 72 m building's sizes on one of two ranks): 1.18 ms, BLAS's product with the four columns 3.22 ms, four
    matrix-vector products 3.50 ms, the product with every column (before) 5.23 ms."""
    n, m = Z.shape
    for i in range(n):
        a0 = 0.0
        a1 = 0.0
        a2 = 0.0
        a3 = 0.0
        for j in range(m):
            z = Z[i, j]
            a0 += z * D[0, j]
            a1 += z * D[1, j]
            a2 += z * D[2, j]
            a3 += z * D[3, j]
        out[i, 0] = a0
        out[i, 1] = a1
        out[i, 2] = a2
        out[i, 3] = a3


class MirroredZ:
    """Collective: the products Z d of each step (``coupling.step``'s x -= Z d) from the orbits' representatives'
    columns alone (module docstring): with Z e_i = s R_g Z e_r for each image i = (g, r, s) of representative column
    r (``RegionColumns.solve``),

        Z d = Z_r d_1 + sum_{g != 1} R_g Z_r d_g,     (d_g)_r = s d_i for the image i of r by g, else 0,

    one pass over Z_r's rows for the |G| right-hand sides together (Z_r: the region's rows x the representatives'
    columns, 390 of the uniform 72 m building's 1425: a step reads that share of Z) and |G| - 1 signed permutations
    of the region's DOFs (``bem.mirror.signed_permutation``, PETSc Mats on the region's rows). ``Z``: every
    column (the set-up's, whose interface rows the step's interface system takes: ``Z_II``), its representatives'
    copied; ``rep_cols``: their columns in Z; ``images[r]``: [(g, column, sign)]; ``R``: {g: R_g}."""

    def __init__(self, Z, rep_cols, images, R):
        self.rep_cols, self.images = np.asarray(rep_cols, np.int64), images
        self.planes = []            # the group's generators [(axis, c)], x_axis = c (``structure_reflections``)
        self.gs = sorted(R)
        self.R = [R[g] for g in self.gs]
        self.Zr = np.ascontiguousarray(Z[:, rep_cols])
        n = len(rep_cols)
        G = 1 + len(self.gs)
        self.idx = np.full((G, n), Z.shape[1], np.int64)     # (the column past the last: d's appended zero)
        self.sgn = np.zeros((G, n))
        self.idx[0], self.sgn[0] = rep_cols, 1.0
        at = {g: j + 1 for j, g in enumerate(self.gs)}
        for r, lst in enumerate(images):
            for g, i, sgn in lst:
                self.idx[at[g], r], self.sgn[at[g], r] = i, sgn
        self.used = [bool(np.any(self.sgn[j + 1])) for j in range(len(self.gs))]   # (the same on every rank)
        self.vin, self.vout = self.R[0].createVecs() if self.R else (None, None)

    @property
    def nbytes(self):
        return self.Zr.nbytes + self.idx.nbytes + self.sgn.nbytes

    def product(self, d):
        """Collective: Z d on this rank's region rows (d: Z's columns, every rank the same)."""
        D = self.sgn * np.append(d, 0.0)[self.idx]                 # (|G|, representatives)
        if D.shape[0] <= 4:
            D4 = np.zeros((4, D.shape[1]))
            D4[:D.shape[0]] = D
            Y = np.empty((self.Zr.shape[0], 4))
            _rows4(self.Zr, D4, Y)
        else:
            Y = self.Zr @ D.T
        out = Y[:, 0].copy()
        for j, R in enumerate(self.R):
            if self.used[j]:
                self.vin.getArray()[:] = Y[:, j + 1]
                R.mult(self.vin, self.vout)
                out += self.vout.getArray(readonly=True)
        return out

    def destroy(self):
        for o in self.R + [v for v in (self.vin, self.vout) if v is not None]:
            o.destroy()
        self.R = []
        self.vin = self.vout = None


def structure_reflections(planes, coords, dofmap, comm, tol=1e-9):
    """Collective: {g: R_g} of the mirror group the planes x_axis = c generate (``bem.mirror.group``'s order of g:
    the generators' products in binary order) as signed permutations of the structure's DOFs (PETSc Mats on the
    dof map's owned rows), or a reason (str) where the structure's nodes (``coords``) do not map onto nodes with
    the same DOFs. A reflection about x_a = c moves a node's translations with the sign -1 on a, its rotations
    (a pseudovector: det R R w) with -1 on the other two axes, and a released rotation triple as the first."""
    from scipy.spatial import cKDTree
    PETSc = init()
    X = np.asarray(coords, float)
    n = len(X)
    if not planes or n == 0:
        return "no mirror planes"
    ext = float(np.ptp(X, axis=0).max()) or 1.0
    tree = cKDTree(X)
    gens = []
    for axis, c in planes:
        Y = X.copy()
        Y[:, axis] = 2.0 * c - Y[:, axis]
        d, j = tree.query(Y)
        if d.max() > tol * ext or not np.array_equal(j[j], np.arange(n)):
            return f"the structure is not symmetric about {'xy'[axis]} = {c:.6g} m"
        if not (np.array_equal(dofmap.ndof[j], dofmap.ndof) and np.array_equal(dofmap.released[j], dofmap.released)):
            return f"the structure's DOFs are not symmetric about {'xy'[axis]} = {c:.6g} m"
        sign = np.ones(9)
        sign[axis] = -1.0                              # translations
        sign[[3 + k for k in range(3) if k != axis]] = -1.0       # rotations (pseudovector)
        sign[6:9] = sign[3:6]                          # the released triple
        gens.append((j.astype(np.int64), sign))
    node = np.repeat(np.arange(n), dofmap.ndof)        # (every DOF's node and its index within the node)
    local = np.arange(dofmap.size) - dofmap.offset[node]
    r0, r1 = dofmap.r0, dofmap.r1
    out = {}
    for bits in range(1, 1 << len(gens)):
        m = np.arange(n)
        sg = np.ones(9)
        for i, (j, sign) in enumerate(gens):
            if bits >> i & 1:
                m = j[m]
                sg = sg * sign
        d = np.arange(r0, r1)
        cols = dofmap.offset[m[node[d]]] + local[d]
        out[bits] = PETSc.Mat().createAIJ(size=((r1 - r0, dofmap.size), (r1 - r0, dofmap.size)), comm=comm,
                                          csr=(np.arange(r1 - r0 + 1).astype(PETSc.IntType),
                                               cols.astype(PETSc.IntType), sg[local[d]].astype(float)))
    return out


def commutation_defect(A, R):
    """Collective: max over the signed permutations R ({g: R_g}) of ||A R_g v - R_g A v||_inf / ||A v||_inf,
    v_j = sin(0.7 j + 0.3) over A's global rows (``bem.mirror.permutation_defect``)."""
    from ..bem.mirror import permutation_defect
    return permutation_defect(init(), A, [R[g] for g in sorted(R)])


def orbit_representatives(maps, nodes_I, where):
    """(reps, img) of the interface nodes under the node maps ``maps`` (|G|, n) of a mirror group
    (``bem.mirror.group``) on the nodes ``where`` numbers (``where[node]``: its index in the maps, -1 outside):
    ``img[g, k]`` the interface node g(k) (positions in ``nodes_I``), ``reps`` the positions that are their
    orbit's smallest; None where an interface node's image is not an interface node (or lies outside the maps'
    nodes)."""
    ri = where[np.asarray(nodes_I, np.int64)]
    if np.any(ri < 0):
        return None
    back = -np.ones(maps.shape[1], np.int64)
    back[ri] = np.arange(ri.size)
    img = back[maps[:, ri]]
    if np.any(img < 0):
        return None
    return np.flatnonzero(img.min(axis=0) == np.arange(ri.size)), img


def estimated_solved_columns(cfg, prob, be_nodes):
    """The interface columns the run solves (``RegionColumns``: on a region with mirror-symmetric blocks, an
    orbit's representative's only, the others their images), before it runs: 3 n_I, or 3 x the orbits'
    representatives on the region of ``estimated_region_nodes`` when the surface (``bem.mirror.blocks_of``)
    and the region mirror and -ssi_step_mirror allows (the commutation assumed, as the estimate's blocks)."""
    return estimated_orbits(cfg, prob, be_nodes)[0]


def estimated_orbits(cfg, prob, be_nodes):
    """(the interface columns solved, ``estimated_solved_columns``; the mirror planes [(axis, c)] of the region, []
    where every column is solved)."""
    n = 3 * len(be_nodes)
    inside = _first_region(cfg, prob, be_nodes)
    if str(cfg.get("step_mirror", "auto")).lower() == "off" or inside is None:
        return n, []
    from ..bem.mirror import blocks_of, group, surface_reflections
    if blocks_of(prob) == 1:
        return n, []
    nodes = np.flatnonzero(inside)
    refl = surface_reflections(prob, nodes)
    if not refl:
        return n, []
    where = -np.ones(prob.mesh.n_nodes, np.int64)
    where[nodes] = np.arange(nodes.size)
    got = orbit_representatives(group(refl)[0], be_nodes, where)
    return (n, []) if got is None else (3 * got[0].size, [(int(a), float(c)) for a, c, _ in refl])


def estimated_fem_solved_columns(cfg, prob, be_nodes, model, comm):
    """Collective: the structure's interface columns the run solves (implicit coupling, ``Coupler.fem_columns``):
    the soil's count (``estimated_solved_columns``) where the structure mirrors about the same planes
    (``structure_reflections``; the checks on its columns assumed to pass), else 3 n_I."""
    n_solved, planes = estimated_orbits(cfg, prob, be_nodes)
    if not planes:
        return 3 * len(be_nodes)
    got = structure_reflections(planes, model.mesh.coords, model.dofmap, comm)
    if isinstance(got, str):
        return 3 * len(be_nodes)
    for R in got.values():
        R.destroy()
    return n_solved


def estimated_region_nodes(cfg, prob, be_nodes):
    """The soil nodes whose rows of Z the run keeps, before it runs (``petsc-ssi estimate``, the memory
    check, the run's first line): the region of ``region_columns`` at its first margin (the same
    ``geometric_reach``); every node where the columns go with the step matrix's factors (full, or auto past
    ``AUTO_SHARE``, or a region of every node). A doubled margin (a residual above round-off) is not foreseen."""
    inside = _first_region(cfg, prob, be_nodes)
    return prob.mesh.n_nodes if inside is None else int(inside.sum())


def _first_region(cfg, prob, be_nodes):
    """The mask of the soil nodes in ``region_columns``' region at its first margin, or None where the columns
    go with the step matrix's factors (full, or auto past ``AUTO_SHARE``, or a region of every node)."""
    N = prob.mesh.n_nodes
    mode = str(cfg.get("interface_columns") or "auto").lower()
    if mode == "full":
        return None
    margin = float(cfg.get("interface_columns_margin") or 4.0) * geometric_reach(cfg, prob)
    inside = region_nodes(prob.mesh.nodes, np.asarray(be_nodes), margin)
    n = int(inside.sum())
    if (mode == "auto" and n > AUTO_SHARE * N) or n == N:
        return None
    return inside
