r"""The interface columns Z = A^{-1} H_s E_I of the coupled step on a region around the interface
(``-ssi_interface_columns``; issue 41's building on a large uniform grid).

A is the soil's step matrix (lags 1-2: a node couples only to the nodes of the elements a wave reaches
within a step or two, at most the *reach* r = c_p t + the largest element diameter apart,
``geometric_reach``). Its inverse decays geometrically away from the diagonal: on the paper's building on
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
"""
import numpy as np

from ..petsc import init, printf, solve_columns, set_default_options, soil_solver_defaults, mumps_failure

# the largest residual of the region's columns, over the column's right-hand side (both in the
# infinity norm), that keeps the region: round-off of the step equations' own size
TOL = 1e-14
# auto: the region when it holds at most this share of the soil's DOFs (the full solve otherwise)
AUTO_SHARE = 0.6
# the region's MUMPS LU: percentage of workspace beyond the analysis' estimate (MUMPS's default 20)
ICNTL14 = 60


def geometric_reach(cfg, prob):
    """The step matrix's reach from the geometry [m]: c_p t + the largest element diameter (t = 2 dt
    stabilised, dt plain: the last lag of the step matrix; an element a wave reaches within t couples all its
    nodes), an upper bound of the distance A couples (3.78 m against 3.5 m read off A on the uniform 72 m
    building, 2.46 against 2.12 m on the 24 m test grid). The run and the estimate both size the region with
    it, so that they take the same region."""
    X, cells = prob.mesh.nodes, prob.mesh.cells
    diam = float(np.linalg.norm(X[cells].max(axis=1) - X[cells].min(axis=1), axis=1).max()) if len(cells) else 0.0
    t = (2.0 if str(cfg.scheme).startswith("stabili") else 1.0) * prob.dt
    return prob.mat.cp * t + diam


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
    region."""

    def __init__(self, march, X, nodes_I, margin, log=printf):
        PETSc = init()
        self.PETSc, self.march, self.comm = PETSc, march, march.comm
        A = march.A
        r0, r1 = A.getOwnershipRange()
        self.inside_nodes = region_nodes(X, nodes_I, margin)
        inside = np.repeat(self.inside_nodes, 3)
        self.X = X
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

        solve_columns(ksp, tmpl, len(cols), fill, take, block=block, Q=None if mb is None else mb.Q)
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

    def _mirror(self, AR):
        """Collective: the region's matrix in mirror-symmetric blocks (``bem.mirror``) when the step matrix's LU
        is (the region around a mirror-symmetric interface is mirror-symmetric too), else None. The columns
        are checked as always (their ring residual), and the blocks' commutation before."""
        m = self.march
        if getattr(m, "mirror", None) is None:
            return None
        from ..bem.mirror import MirrorBlocks
        nodes = np.flatnonzero(self.inside_nodes)
        where = -np.ones(len(self.X), np.int64)
        where[nodes] = np.arange(nodes.size)
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
    region) allows it: (rows, Z, line) with ``line`` the log's account, or None (the caller solves with A's
    factors: full, a region holding most of the grid, or no region within the margins tried)."""
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
                    f"{' (mirror-symmetric blocks, as the step matrix)' if reg.mirrored else ''}; truncation residual {reg.residual:.2e} of "
                    f"the right-hand sides (<= {TOL:g}; -ssi_interface_columns)"
                    + (f"; tried first: {', '.join(tried)}" if tried else ""))
            return reg.rows, reg.Z, line
        tried.append(f"{margin:.3g} m: residual {reg.residual:.2e}"
                     + (", a right-hand side outside" if reg.rhs_outside else ""))
        margin *= 2.0


def estimated_region_nodes(cfg, prob, be_nodes):
    """The soil nodes whose rows of Z the run keeps, before it runs (``petsc-ssi estimate``, the memory
    check, the run's first line): the region of ``region_columns`` at its first margin (the same
    ``geometric_reach``); every node where the columns go with the step matrix's factors (full, or auto past
    ``AUTO_SHARE``, or a region of every node). A doubled margin (a residual above round-off) is not foreseen."""
    N = prob.mesh.n_nodes
    mode = str(cfg.get("interface_columns") or "auto").lower()
    if mode == "full":
        return N
    margin = float(cfg.get("interface_columns_margin") or 4.0) * geometric_reach(cfg, prob)
    n = int(region_nodes(prob.mesh.nodes, np.asarray(be_nodes), margin).sum())
    if (mode == "auto" and n > AUTO_SHARE * N) or n == N:
        return N
    return n
