r"""Time marching of the BEM (paper eqs. 6-7; method notes section 2).

Step equations E_n: sum_{m<=n} H_{n-m+1} u^m = sum_{m<=n} G_{n-m+1} p^m.

plain (eq. 6):       H_1 u^n - G_1 p^n = sum_{j>=2} [G_j x_j(p) - H_j x_j(u)],
                     x_j(v) = v^{n-j+1}
stabilized (eq. 7):  E_{n+1} + 2 E_n + E_{n-1}, with u^{n+1} = 2u^n - u^{n-1}
                     and p^{n+1} = 2p^n - p^{n-1} (extrapolated; for KNOWN
                     values too, so the scheme is one linear combination of
                     step equations for every boundary condition):
   (4H_1 + H_2) u^n - (4G_1 + G_2) p^n = sum_{j>=2} [G_j q_j(p) - H_j q_j(u)],
   q_j(v) = v^{n-j+2} + 2 v^{n-j+1} + v^{n-j}, terms with index in 1..n-1.
The terms H_1 u^{n-1} - G_1 p^{n-1} of eq. 7 cancel the j = 1 history term
exactly, so the sum starts at j = 2 (paper eq. 8 prints u^{n-m-2} for
u^{n-m+2}: a typo, the G-term shows the right index).

Unknowns: u at free nodes, p at nodes of prescribed-displacement regions.
The step matrix A (u columns of H_s, p columns of -G_s) is local and sparse:
AIJ, factorised once (KSP prefix ``ssi_bem_``: preonly + LU with MUMPS by
default, any KSP/PC from the options database). The history sum runs over the
stored lags with past states in a ring buffer of fixed length.
"""
import time

import numpy as np

from ..petsc import (init, set_default_options, soil_solver_defaults, printf, check_reproducible_solver,
                     mumps_failure, mumps_factor_info, solve_columns, SSIError)
from ..monitor import event

# (bsr, the block-sparse kernels, is imported where it is used: numba's import waits for a run that
# multiplies; bem/lagset.py)
BLOCK_MAX = 32          # the largest -ssi_history_block (the ring buffer's extra depth)


def block_terms(n, lags, b, s, stabilized=True):
    """How the time-blocked history sum (``Marcher``, blocks of b steps, sub-blocks of s) takes a
    stored matrix that stands for ``lags`` (one lag, or the far lags of one interpolating matrix) over
    the steps ``n`` (array): (steps with a per-step product, summed width of its block panel products,
    summed width of its sub-block panel products). Step n (block start n0 = b floor((n-1)/b), sub-block
    start n1 = n0 + s floor((n-n0-1)/s)) reads states m = n - l + o (o in 2, 1, 0 stabilised, 1 plain;
    1 <= m <= n - 1) of lag l: those <= n0 in the block's panel product (width b), those in
    n0 < m <= n1 in the sub-block's (width min(s, n0 + b - n1)), the others in a product of step n.
    The run's last block is b wide too, past the run's end: a narrower panel rounds differently
    (BLAS and the block-sparse kernel treat a panel's columns by its width), and a step's numbers
    must not depend on how many steps the run takes (a stopped run equals a shorter one bit for
    bit: tests/test_output_survives.py)."""
    n = np.asarray(n)
    n0 = b * ((n - 1) // b)
    n1 = n0 + s * ((n - n0 - 1) // s)
    offs = (2, 1, 0) if stabilized else (1,)
    known = np.zeros(n.size, bool)
    sub = np.zeros(n.size, bool)
    step = np.zeros(n.size, bool)
    for lag in lags:
        for o in offs:
            m = n - lag + o
            ok = (m >= 1) & (m <= n - 1)
            known |= ok & (m <= n0)
            sub |= ok & (m > n0) & (m <= n1)
            step |= ok & (m > n1)
    starts = np.unique(n1[sub])
    wsub = int(np.sum(np.minimum(s, b * ((starts - 1) // b + 1) - starts))) if starts.size else 0
    return int(np.count_nonzero(step)), b * len(np.unique(n0[known])), wsub


def step_matrix(comm, lagset, scheme, pres_node_mask):
    """Collective: AIJ step matrix from the lag-1 and lag-2 triplets."""
    PETSc = init()
    r0, r1 = lagset.node_range
    nloc = r1 - r0
    N = lagset.mesh.n_nodes
    coefs = {1: 4.0, 2: 1.0} if scheme == "stabilized" else {1: 1.0}
    Rs, Cs, Vs = [], [], []
    H = lagset.H
    G = lagset.G
    reg = lagset.regions
    for lag, c in coefs.items():
        hr, hc, hv = H.peek(lag)
        m = ~pres_node_mask[hc]
        Rs.append(hr[m]); Cs.append(hc[m]); Vs.append(c * hv[m])
        if reg.n_disp:
            gr, gc, gv = G.peek(lag)
            m = gc >= reg.n_load
            Rs.append(gr[m]); Cs.append(reg.tnode[gc[m]]); Vs.append(-c * gv[m])
    # (the flat surface's exact zeros in the 3 x 3 blocks (H: 5 of 9) left out of the factorisation,
    # measured: 15-20 % less LU and solve time on a uniform grid; diagonal entries kept: bsr.block_csr)
    from .bsr import block_csr
    ip, ix, dv = block_csr(np.concatenate(Rs).astype(np.int64) - r0, np.concatenate(Cs).astype(np.int64),
                           np.ascontiguousarray(np.concatenate(Vs).reshape(-1, 3, 3), dtype=float), nloc, r0)
    M = PETSc.Mat().createAIJ(size=((3 * nloc, 3 * N), (3 * nloc, 3 * N)), bsize=3,
                              csr=(ip.astype(PETSc.IntType), ix.astype(PETSc.IntType), dv), comm=comm)
    M.assemble()
    return M


# -ssi_step_blr auto: MUMPS's block low-rank LU (ICNTL(35) 2, CNTL(7) BLR_EPS) for step matrices of at least
# BLR_FROM DOFs, where its step solves are faster (jobscripts/building_uniform.sh, uniform-72 against
# uniform-72-fullrank: runs/building/README.md); the factors are checked on a test right-hand side
BLR_EPS = 1e-15
BLR_FROM = 20000
# the largest residual of the block low-rank factors on a test right-hand side: else the full-rank LU
BLR_TOL = 1e-12


def blr_precision(opt, n_dofs):
    """The BLR precision of the step matrix's LU (0: full rank) for -ssi_step_blr ``opt`` (-1 auto:
    ``BLR_EPS`` from ``BLR_FROM`` DOFs on, full rank below; 0 full rank; > 0 that precision)."""
    if opt < 0:
        return BLR_EPS if n_dofs >= BLR_FROM else 0.0
    return float(opt)


class Marcher:
    """Collective: steps the BEM in time. ``H``, ``G``: lists of Mats (lag 1..L)."""

    def __init__(self, comm, lagset, scheme, known_u, known_p, log=printf, zero_dofs=(), A=None, blr=0.0,
                 mirror="auto"):
        """Collective: step matrix and its factorisation (from the lag-1 and
        lag-2 triplets of ``lagset``, or ``A`` as saved, ``bem.lagstore``); ``set_lags`` then
        hands over the Mats. ``blr``: -ssi_step_blr (``blr_precision``); ``mirror``: -ssi_step_mirror (auto:
        the LU of the mirror-symmetric blocks where the surface has mirror planes, ``bem.mirror``; off)."""
        PETSc = init()
        self.PETSc = PETSc
        self.comm = comm
        self.L = lagset.L
        self.scheme = "stabilized" if scheme.startswith("stabili") else "plain"
        reg = lagset.regions
        self.reg = reg
        N = lagset.mesh.n_nodes
        self.N = N
        self.nt = reg.n_t
        pres = np.zeros(N, bool)
        pres[reg.disp_nodes] = True
        self.pres = pres
        ev = event("SSI_BEM_Factor")
        ev.begin()
        t0 = time.perf_counter()
        self.A = step_matrix(comm, lagset, self.scheme, pres) if A is None else A
        # DOFs a symmetry plane forces to zero: identity rows, zero columns
        # (their equations involve only these DOFs; see symmetry.zero_dofs)
        r0, r1 = self.A.getOwnershipRange()
        zd = np.asarray(zero_dofs, dtype=np.int64)
        zd = zd[(zd >= r0) & (zd < r1)]
        self.A.zeroRowsColumns(zd.astype(PETSc.IntType), diag=1.0)
        self.zero_local = zd - r0
        set_default_options("ssi_bem_", soil_solver_defaults(comm), log)
        check_reproducible_solver("ssi_bem_", comm, "the soil's step matrix")
        eps = blr_precision(blr, self.A.getSize()[0])
        self.mirror = None
        mirror_note = self._mirror_blocks(lagset, str(mirror).lower(), len(zero_dofs))
        if not self._factorise(eps):
            if blr > 0:                 # (asked for, not possible: said, not silently full rank)
                printf(f"[ssi] -ssi_step_blr {blr:g}: the step matrix is not factorised by MUMPS's LU here, or "
                       "-ssi_bem_mat_mumps_icntl_35 is given: its own solver options decide")
            eps = 0.0
        blr_note, eps = self._check_blr(eps, blr) if eps > 0.0 else ("", 0.0)
        if self.mirror is not None:
            res = self._test_residual()
            tol = self._test_tol(eps, blr)
            if not res <= tol:                   # (NaN too): A's own LU, said
                printf(f"[ssi] step matrix: its mirror-symmetric blocks left a residual {res:.3g} > {tol:g} on a "
                       "test right-hand side; factorised as it is instead (-ssi_step_mirror)")
                self._drop_mirror()
                self.ksp.destroy()
                mirror_note = ""
                if not self._factorise(eps):
                    eps = 0.0
                blr_note, eps = self._check_blr(eps, blr) if eps > 0.0 else ("", 0.0)
            else:
                mirror_note += f"; test residual {res:.2g})"
        self.t_factor = time.perf_counter() - t0       # step matrix + factorisation
        info = mumps_factor_info(self.ksp)
        if info:                # (one line, monitor or not: the factors' bytes bound each step's solve)
            printf(f"[ssi] step matrix: {self.A.getSize()[0]} DOFs, {info}{blr_note}{mirror_note}")
        elif mirror_note:
            printf(f"[ssi] step matrix: {self.A.getSize()[0]} DOFs{mirror_note}")
        ev.end()
        self.known_u = known_u      # callable(n) -> prescribed u values at disp DOFs (3*n_disp,)
        self.known_p = known_p      # callable(n) -> traction at load DOFs (3*n_load,)
        self.norm_prefix_max = []   # the divergence guard's running max of |u| (bem/stability.py guard)
        self.u_tmpl = self.A.createVecRight()
        self.n = 0
        self.toeplitz = []          # bem/toeplitz.ToeplitzHistory per side: the H (and G) lags >= 3 as FFT kernels
        self.area = None            # bem/area.AreaHistory: the area loads' terms of each step (-ssi_load_area)

    def _mirror_blocks(self, lagset, mode, n_zero):
        """Collective: with -ssi_step_mirror auto and a surface with mirror planes (``bem.mirror``), the block
        diagonal Q^T A Q that ``_factorise`` factorises (``self.mirror``); returns the log's note ('' when not
        used, with a line saying why when the surface's nodes mirror but A does not)."""
        nimg = getattr(lagset, "n_images", None) or len(lagset.Vc) // max(lagset.mesh.n_cells, 1)
        if mode == "off" or n_zero or nimg > 1:
            return ""                           # (symmetry planes: the model is already reduced)
        db = self.PETSc.Options()               # (a direct solve only: the defaults' preonly + LU, or the user's)
        if (db.getString("ssi_bem_ksp_type", "preonly") != "preonly"
                or db.getString("ssi_bem_pc_type", "lu") not in ("lu", "cholesky")):
            return ""
        from .mirror import MirrorBlocks
        reg = self.reg
        mb = MirrorBlocks(self.PETSc, self.comm, self.A, lagset.mesh.nodes, self.pres,
                          np.asarray(reg.tnode)[reg.n_load:] if reg.n_t else [])
        if mb.why:
            if mb.defect == mb.defect:          # (the nodes mirror: say why A's own LU)
                printf(f"[ssi] step matrix: factorised as it is: {mb.why} (-ssi_step_mirror)")
            mb.destroy()
            return ""
        self.mirror = mb
        return (f", mirror-symmetric about {mb.planes}: {len(mb.sizes)} independent blocks of "
                f"{'/'.join(str(n) for n in mb.sizes)} DOFs (-ssi_step_mirror; commutation defect {mb.defect:.2g}")

    def _drop_mirror(self):
        self.mirror.destroy()
        self.mirror = None

    def _factorise(self, eps=0.0):
        """Collective: the KSP of the step matrix, set up (factorised) with the ssi_bem_ options; with ``eps``
        > 0 and a MUMPS LU whose ICNTL(35) the user did not set, in block low-rank form at precision eps (set on
        the factor, not in the options database: the next run in the process starts from full rank). Returns
        whether the factors are block low-rank."""
        PETSc = self.PETSc
        self.ksp = PETSc.KSP().create(comm=self.comm)
        self.ksp.setOptionsPrefix("ssi_bem_")
        self.ksp.setOperators(self.A if self.mirror is None else self.mirror.Ap)
        self.ksp.setFromOptions()
        pc = self.ksp.getPC()
        blr = (eps > 0.0 and self.ksp.getType() == "preonly" and pc.getType() == "lu"
               and pc.getFactorSolverType() == "mumps" and not PETSc.Options().hasName("ssi_bem_mat_mumps_icntl_35"))
        if blr:
            pc.setFactorSetUpSolverType()
            F = pc.getFactorMatrix()
            F.setMumpsIcntl(35, 2)
            F.setMumpsCntl(7, eps)
        self.ksp.setUp()
        failed = mumps_failure(self.ksp)        # (INFOG is global: every rank raises)
        if failed:
            raise SSIError(f"the soil's step matrix ({self.A.getSize()[0]} DOFs): {failed}; more workspace with "
                           "-ssi_bem_mat_mumps_icntl_14 <percent> (default 20), more memory with "
                           "-ssi_bem_mat_mumps_icntl_23 <MB per rank>, or fewer DOFs")
        return blr

    def _test_residual(self):
        """Collective: ||A x - b|| / ||b|| of the step solve (``solve``'s path, its factors) on a fixed test
        right-hand side (``mirror.solve_residual``), A the step matrix itself."""
        from .mirror import solve_residual
        return solve_residual(self.A, self._solve, self.zero_local)

    @staticmethod
    def _test_tol(eps, blr):
        """The test residual's bound: ``BLR_TOL``, or 100 eps for a block low-rank precision the user chose."""
        return BLR_TOL if (blr < 0 or eps <= 0.0) else max(BLR_TOL, 100.0 * eps)

    def _check_blr(self, eps, blr):
        """Collective: the block low-rank factors checked on a fixed test right-hand side (``_test_residual``):
        at most ``_test_tol``, else the full-rank LU instead, said in one line. Returns (the log's note, the
        precision the factors have: eps, or 0 after the fallback)."""
        res = self._test_residual()
        tol = self._test_tol(eps, blr)
        if not res <= tol:                       # (NaN too)
            printf(f"[ssi] step matrix: the block low-rank LU at eps {eps:g} left a residual {res:.3g} > {tol:g} on "
                "a test right-hand side; factorised in full rank instead (-ssi_step_blr)")
            self.ksp.destroy()
            self._factorise()
            return "", 0.0
        return f", block low-rank at eps {eps:g} (-ssi_step_blr; test residual {res:.2g})", eps

    def set_lags(self, H, G, plan=None, HI=(), GI=(), block=1, sub=None):
        """Collective: the exact lag Mats H_l, G_l (lists, index l-1; None =
        empty) and, with an active interpolation ``plan``, the interpolating
        Mats HI[j] = H(T_j), GI[j] = G(T_j) that stand for lags plan.Lx+1..L; ``block``: the
        steps of the time-blocked history sum (1: step by step); ``sub``: the steps of its
        sub-blocks (None or >= block: one level)."""
        self.H, self.G = H, G
        self.plan = plan if (plan is not None and plan.active) else None
        self.HI, self.GI = list(HI), list(GI)
        self.p_tmpl = self._p_vec()
        self.block = max(1, int(block))
        self.sub = self.block if not sub or sub >= self.block else max(1, int(sub))
        # the ring buffer: the L + 2 states the history sum reads and BLOCK_MAX - 1 more, whatever b
        # is: a block starts at a multiple of b, also after a restart (the same sums as an
        # uninterrupted run), and a checkpoint holds what any b <= BLOCK_MAX needs, so a restart
        # on another rank count, whose automatic b may differ, has every state it reads
        self.depth = self.L + 2 + (BLOCK_MAX - 1)
        # every rank's copies of the states for the panel products (``_replicate``): as deep as the Mats'
        # lags reach from a block's start through its b <= BLOCK_MAX steps; all of the ring when an
        # interpolating Mat weighs far states (on the toeplitz store only lags 1-2 are Mats: 37 states, not
        # L + 33 states of every DOF on every rank)
        lmat = max([j + 1 for Ms in (H, G) for j, M in enumerate(Ms) if M is not None] + [0])
        far = any(M is not None for M in self.HI + self.GI)
        self.rep_depth = self.depth if far else min(self.depth, lmat + 3 + BLOCK_MAX)
        self.ubuf = [self.u_tmpl.duplicate() for _ in range(self.depth)]
        self.pbuf = [self.p_tmpl.duplicate() for _ in range(self.depth)]
        self._setup_index_maps()
        self.rhs = self.u_tmpl.duplicate()
        self.x = self.u_tmpl.duplicate()
        self.wu = self.u_tmpl.duplicate()
        self.wp = self.p_tmpl.duplicate()
        self._blk = self._rep = self._R = None

    def _p_vec(self):
        PETSc = self.PETSc
        for M in self.G:
            if M is not None:
                return M.createVecRight()
        return PETSc.Vec().createMPI((PETSc.DECIDE, 3 * self.nt), bsize=3, comm=self.comm)

    def _setup_index_maps(self):
        """Scatters between the unknown vector and the u / p vectors."""
        PETSc = self.PETSc
        reg = self.reg
        dn = reg.disp_nodes
        dofs = (3 * dn[:, None] + np.arange(3)).ravel().astype(np.int32)
        tdofs = (3 * (reg.n_load + np.arange(reg.n_disp))[:, None] + np.arange(3)).ravel().astype(np.int32)
        ldofs = (3 * np.arange(reg.n_load)[:, None] + np.arange(3)).ravel().astype(np.int32)
        rank = self.comm.getRank()
        # every rank sets what it owns; index sets built from rank 0's share to avoid duplicates
        take = lambda a: a if rank == 0 else a[:0]
        self.is_pres_u = PETSc.IS().createGeneral(take(dofs), comm=self.comm)
        self.is_pres_p = PETSc.IS().createGeneral(take(tdofs), comm=self.comm)
        self.is_load_p = PETSc.IS().createGeneral(take(ldofs), comm=self.comm)
        self.sc_x2p = PETSc.Scatter().create(self.u_tmpl, self.is_pres_u, self.p_tmpl, self.is_pres_p)
        self.kv_u = self.u_tmpl.duplicate()   # known u at prescribed DOFs (zero elsewhere)
        self.kv_p = self.p_tmpl.duplicate()   # known p at load DOFs (zero elsewhere)
        self.dofs_pres = dofs
        self.dofs_load = ldofs

    # ------------------------------------------------------------ the public coupling API
    # Known values: traction at load DOFs (a replicated history, set by rank 0 and assembled)
    # and displacement at prescribed DOFs, either from the prescribed history (rank 0) or set
    # by the rank that owns each DOF (the FEM-BEM coupling: the structure's interface
    # displacement), without communication.
    def coefficients(self):
        """((lag, c), ...): the step matrix's lag coefficients, A = sum c (H_lag | -G_lag) (stabilised
        4 H_1 + H_2, plain H_1): the one place the scheme's coefficients live."""
        return ((1, 4.0), (2, 1.0)) if self.scheme == "stabilized" else ((1, 1.0),)

    def set_known_p(self, n):
        """Collective: the known traction of step n into kv_p (rank 0 sets, assembled)."""
        self.kv_p.set(0.0)
        if self.comm.getRank() == 0 and self.reg.n_load:
            self.kv_p.setValues(self.dofs_load, self.known_p(n))
        self.kv_p.assemblyBegin(); self.kv_p.assemblyEnd()

    def set_known_u_owned(self, local, values):
        """Local (no communication): kv_u = 0, then kv_u[local] = values at DOFs this rank owns
        (``local``: indices into the owned part)."""
        kv = self.kv_u.getArray()
        kv[:] = 0.0
        kv[np.asarray(local, np.int64)] = values
        return kv

    def mult_step_H(self, x, out):
        """Collective: out = H_s x = sum c H_lag x (the step matrix's displacement part), rows of
        symmetry-zero DOFs set to 0."""
        out.set(0.0)
        if not hasattr(self, "_t"):
            self._t = self.u_tmpl.duplicate()
        for lag, c in self.coefficients():
            self.H[lag - 1].mult(x, self._t)
            out.axpy(c, self._t)
        if self.zero_local.size:
            out.getArray()[self.zero_local] = 0.0
        return out

    def step_H_columns(self, dofs):
        """The columns ``dofs`` (global DOFs) of H_s = sum c H_lag, this rank's rows, as a dense (local
        rows, len(dofs)) array: ``mult_step_H`` of the unit vectors, read off the lags' blocks
        (``bsr.columns``; the sum in mult_step_H's order), rows of symmetry-zero DOFs 0; None where a
        lag is a Mat whose columns are not read off (dense PETSc Mats, loaded AIJ) on any rank: multiply
        instead. Collective (the ranks agree on None: the fallback's products are collective); the
        coefficients are 1 and 4, so c H_1 e + H_2 e rounds as mult_step_H's VecAXPYs do."""
        from . import bsr
        out = None
        for lag, c in self.coefficients():
            col = bsr.columns(self.H[lag - 1], dofs)
            if col is None:
                out = None
                break
            if c != 1.0:
                col *= c                        # (in place: the chunk's arrays stay two)
            if out is None:
                out = col
            else:
                out += col
        from mpi4py import MPI
        if not self.comm.tompi4py().allreduce(out is not None, op=MPI.LAND):
            return None
        if self.zero_local.size:
            out[self.zero_local] = 0.0
        return out

    def residual(self, x, b, out):
        """Collective: out = A x - b (the step equations)."""
        self.A.mult(x, out)
        out.axpy(-1.0, b)
        return out

    @property
    def history_rhs(self):
        """The right-hand side of the current step after ``begin_step`` (the history sum)."""
        return self._b

    def _set_known(self, n):
        """Known values of step n into kv_u / kv_p (set by rank 0, assembled)."""
        self.kv_u.set(0.0)
        if self.comm.getRank() == 0 and self.reg.n_disp:
            self.kv_u.setValues(self.dofs_pres, self.known_u(n))
        self.kv_u.assemblyBegin(); self.kv_u.assemblyEnd()
        self.set_known_p(n)

    def _slot(self, m):
        return m % self.depth

    def _rslot(self, m):
        """The row of state m in every rank's copies (``_replicate``)."""
        return m % self.rep_depth

    def _terms(self, n, j):
        """(state index m, coefficient) of q_j at step n, indices in 1..n-1."""
        if self.scheme == "stabilized":
            terms = [(n - j + 2, 1.0), (n - j + 1, 2.0), (n - j, 1.0)]
        else:
            terms = [(n - j + 1, 1.0)]
        return [(m, c) for m, c in terms if 1 <= m <= n - 1]

    def history(self, n, out_u):
        """out = sum_{j>=2} [G_j q_j(p) - H_j q_j(u)] for step n: time-blocked
        (``_blocked_history``) when ``block`` > 1, else step by step (``history_step``)."""
        if self.block > 1:
            self._blocked_history(n, out_u)
        else:
            self.history_step(n, out_u)
        if self.toeplitz:                   # the H and G lags of a uniform grid in Fourier space (bem/toeplitz.py)
            ev = event("SSI_BEM_HistFFT")
            ev.begin()
            for side in self.toeplitz:
                side.add(n, self, out_u)
            ev.end()

    def history_step(self, n, out_u):
        """The per-step history sum (the reference): one product per lag; lags beyond
        the plan's exact ones through the interpolating matrices: the weighted
        history w_i = sum_l I(l, i) q_l is formed first, then one product per
        interpolating matrix (k products per step, not one per lag)."""
        out_u.set(0.0)
        jmax = min(len(self.H), n + 1)
        if self.plan is not None:
            self._interp_history(n, out_u)
        for j in range(2, jmax + 1):
            terms = self._terms(n, j)
            if not terms:
                continue
            Hj = self.H[j - 1]
            Gj = self.G[j - 1] if j - 1 < len(self.G) else None
            if Hj is not None:
                self._combine(self.wu, self.ubuf, terms)
                Hj.mult(self.wu, self.rhs)
                out_u.axpy(-1.0, self.rhs)
            if Gj is not None:
                self._combine(self.wp, self.pbuf, terms)
                Gj.multAdd(self.wp, out_u, out_u)

    def _interp_coef(self, n):
        """coef[m, i]: the weight of state m in the interpolated history w_i of step n (None: no
        interpolated lag reaches a state yet): ``interp.state_weights``."""
        from .interp import state_weights
        return state_weights(self.plan, n, self.scheme == "stabilized")

    def _interp_history(self, n, out_u):
        plan = self.plan
        coef = self._interp_coef(n)
        if coef is None:
            return
        ms = np.nonzero(np.any(coef != 0.0, axis=1))[0]
        if ms.size == 0:
            return
        for i in range(plan.k):
            terms = [(int(m), float(coef[m, i])) for m in ms]
            if self.HI[i] is not None:
                self._combine(self.wu, self.ubuf, terms)
                self.HI[i].mult(self.wu, self.rhs)
                out_u.axpy(-1.0, self.rhs)
            if self.GI and self.GI[i] is not None:
                self._combine(self.wp, self.pbuf, terms)
                self.GI[i].multAdd(self.wp, out_u, out_u)

    # ------------------------------------------------------------ the time-blocked history sum
    # The history sum is a discrete convolution with stationary matrices: the part of the history
    # sums of the next b steps n0+1 .. n0+b that involves only states already known (m <= n0) is
    # formed at the block's first step. For each dense matrix (MATDENSE: each rank holds its rows
    # and every column) it is one BLAS-3 product of the local rows with a panel of b combined
    # states, taken from copies of the known states that every rank keeps (one all-gather per
    # state, the data a dense MatMult gathers anyway); for each block-sparse one (``bsr``) one
    # compiled pass over its 3x3 blocks: each stored matrix is read once per b steps instead of b
    # times. The terms of states inside the block (m > n0; low lags only, j <= b + 1) go the same
    # way one level down: the block is cut into sub-blocks of s steps (``sub``, -ssi_history_sub), and
    # at the start n1 of each the terms of the block's states n0 < m <= n1 onto the sub-block's steps
    # are one more panel product (width s); only the terms of states inside the sub-block (m > n1,
    # lags j <= s + 1) and any other Mat type go step by step as in ``history_step``. Which terms go
    # where is counted by ``block_terms`` (the cost model and the automatic choice of b and s).
    # The same terms in another order: equal to round-off (tests/bem/test_history_block.py).
    # Blocks start at multiples of b (n0 = 0, b, 2b, ...), also when a restart resumes inside one
    # (its known states are in the ring buffer and the checkpoint), so a restart is bitwise the
    # uninterrupted run; a contact iteration changes only the current step's state, which no block
    # reads before the step is final.
    def _step_terms(self, n):
        """[(key, state m, coefficient)] of step n's history sum: key ('x', j) the exact lag j
        (-H_j on u, +G_j on p), ('i', i) the i-th interpolating matrix (-HI_i, +GI_i)."""
        out = []
        for j in range(2, min(len(self.H), n + 1) + 1):
            out += [(("x", j), m, c) for m, c in self._terms(n, j)]
        if self.plan is not None:
            coef = self._interp_coef(n)
            if coef is not None:
                ms, ii = np.nonzero(coef)
                out += [(("i", int(i)), int(m), float(coef[m, i])) for m, i in zip(ms, ii)]
        return out

    def _mat(self, key, side):
        """The Mat of a history key on side 'u' (applied to u, sign -1) or 'p' (to p, +1); None: empty."""
        kind, j = key
        if kind == "x":
            if side == "u":
                return self.H[j - 1]
            return self.G[j - 1] if j - 1 < len(self.G) else None
        if side == "u":
            return self.HI[j]
        return self.GI[j] if self.GI else None

    def _replicate(self, n0):
        """Collective: every rank's copies of the states m <= n0 the block reads (all-gathered once
        per state: the copies of earlier blocks stay valid, their states being final)."""
        from . import bsr
        if getattr(self, "_rep", None) is None:
            self._rep, self._pctx, reads = {}, {}, {}
            for side, tmpl in (("u", self.u_tmpl), ("p", self.p_tmpl)):
                # (the block-sparse Mats' copies hold the columns their rows hold blocks in, compacted where that
                # saves memory: bsr.reader; a dense Mat on a side, every column)
                Ms = self._side_mats(side)
                ctxs = [bsr.context(M) for M in Ms]
                if any(c is None or c.kind == "dense" for c in ctxs):
                    sc, seq, read, moved = *self.PETSc.Scatter.toAll(tmpl), ctxs, tmpl.getSize()
                else:
                    sc, seq, read, moved = bsr.reader(ctxs, tmpl, self.rep_depth)
                for M, c in zip(Ms, read):
                    self._pctx[M.handle] = c
                self._rep[side] = (sc, seq, np.zeros((self.rep_depth, seq.getSize())))
                reads[side] = (moved, seq.getSize(), tmpl.getSize())
            self._rep_upto = 0
            self._say_reads(reads)
        lo = max(self._rep_upto + 1, n0 - self.rep_depth + 1, 1)
        for m in range(lo, n0 + 1):
            for side, bufs in (("u", self.ubuf), ("p", self.pbuf)):
                sc, seq, arr = self._rep[side]
                if arr.shape[1] == 0:
                    continue
                sc.scatter(bufs[self._slot(m)], seq, addv=self.PETSc.InsertMode.INSERT_VALUES)
                arr[self._rslot(m)] = seq.getArray(readonly=True)
        self._rep_upto = max(self._rep_upto, n0)

    def _new_block(self, n0):
        """Collective: the known-state part of the panel matrices' history sums of steps
        n0+1 .. n0+b into ``self._R`` (b x local rows); the terms of states inside the block kept for
        the sub-block panels (``self.sub`` steps each) and for ``_blocked_history`` step by step."""
        b, s = self.block, self.sub
        nsub = -(-b // s)
        panel, subs, rest = {}, [dict() for _ in range(nsub)], [dict() for _ in range(b)]
        for k in range(b):
            i = k // s
            n1 = n0 + i * s                                   # the sub-block's start: states <= n1 final
            for key, m, c in self._step_terms(n0 + 1 + k):
                for side in ("u", "p"):
                    M = self._mat(key, side)
                    if M is None:
                        continue
                    if not self._panel_kind(M):
                        rest[k].setdefault((key, side), []).append((m, c))
                    elif m <= n0:
                        panel.setdefault((key, side), []).append((k, m, c))
                    elif m <= n1:
                        subs[i].setdefault((key, side), []).append((k - i * s, m, c))
                    else:
                        rest[k].setdefault((key, side), []).append((m, c))
        if getattr(self, "_R", None) is None or self._R.shape[0] != b:
            self._R = np.zeros((b, self.u_tmpl.getLocalSize()))        # row k: step n0 + 1 + k
        self._R[...] = 0.0
        if panel:
            self._panel_products(panel, self._R, n0)
        self._blk = (n0, rest, subs)
        self._sub_done = 0                                  # the sub-block whose panel R has last taken

    def _say_reads(self, reads):
        """Collective: one log line, once, where a rank's copies of the states hold less than the whole state
        (``bsr.reader``): the most DOFs a rank moves a state and keeps, of every DOF, per side."""
        if getattr(self, "_said_reads", False):
            return
        self._said_reads = True
        from mpi4py import MPI
        big = self.comm.tompi4py().allreduce([v for s in ("u", "p") for v in reads[s][:2]], op=MPI.MAX)
        if big[0] >= reads["u"][2] and big[2] >= reads["p"][2]:
            return                                          # (every rank all-gathers both: the dense lags)
        printf(f"[ssi] history: the lag Mats' panel products read each rank's rows' columns: a rank moves at "
               f"most {big[0]} and keeps {big[1]} of {reads['u'][2]} displacement DOFs, moves {big[2]} and keeps "
               f"{big[3]} of {reads['p'][2]} traction DOFs a state, {self.rep_depth} states (bem/bsr.py reader)")

    def release(self):
        """Collective: destroy the lag Mats (H, G, the interpolating ones; their python contexts, which hold the Mats
        back, with them) and the every-rank copies, so that a process that runs one problem after another
        (``petsc-ssi impedance``'s modes) does not keep each one's lags."""
        for Ms in (self.H, self.G, self.HI, self.GI):
            for i, M in enumerate(Ms):
                if M is not None:
                    M.destroy()
                    Ms[i] = None
        self._rep = self._pctx = self._R = self._blk = None

    def _side_mats(self, side):
        """The Mats the panel products take on ``side`` ('u': H's, 'p': G's): every exact lag from 2 on and the
        interpolating matrices, those of ``_panel_kind`` (the others multiply PETSc Vecs)."""
        keys = [("x", j) for j in range(2, len(self.H) + 1)] + [("i", i) for i in range(len(self.HI))]
        out, seen = [], set()
        for key in keys:
            M = self._mat(key, side)
            if M is not None and self._panel_kind(M) and M.handle not in seen:
                seen.add(M.handle)
                out.append(M)
        return out

    def _ctx(self, M):
        """The context whose products read the every-rank copies of ``_replicate`` (``bsr.reader``)."""
        return self._pctx[M.handle]

    def _panel_products(self, panel, R, upto):
        """Collective: R (w x local rows) += the panel products of ``panel`` {(key, side): [(row k
        of R, state m, coefficient)]}, states m <= ``upto`` (final) from every rank's copies."""
        from . import bsr
        w = R.shape[0]
        self._replicate(upto)
        bufs = {}                                         # the panel per side and layout, made once
        RT = None
        for (key, side) in sorted(panel):
            M = self._mat(key, side)
            rep = self._rep[side][2]
            kind = self._panel_kind(M)
            shape = (w, rep.shape[1]) if kind == "dense" else (rep.shape[1], w)    # (block-sparse: X^T)
            x = bufs.get((side, shape))
            if x is None:
                x = bufs[(side, shape)] = np.empty(shape)
            x[...] = 0.0
            terms = panel[(key, side)]
            bsr.panel_states(rep, np.array([k for k, _, _ in terms], np.int64),
                             np.array([self._rslot(m) for _, m, _ in terms], np.int64),
                             np.array([c for _, _, c in terms], float), x, kind != "dense")
            sign = -1.0 if side == "u" else 1.0
            if kind == "dense":
                At = M.getDenseArray(readonly=True).T     # all columns x local rows, C order
                self.PETSc.Log.logFlops(2.0 * x.size * At.shape[1])
                if side == "u":                           # (x @ At: OpenBLAS's fast layout
                    R -= x @ At                           # for a skinny panel, twice A @ x.T)
                else:
                    R += x @ At
            else:                                         # block-sparse: one pass over its blocks
                ctx = self._ctx(M)                        # (bsr.BSRMat, SplitBSR or DenseSplit)
                if RT is None:
                    RT = np.zeros((R.shape[1], w))
                ctx.panel(x, RT, sign)
                self.PETSc.Log.logFlops(ctx.flops(w))
        if RT is not None:
            R += RT.T

    @staticmethod
    def _panel_kind(M):
        """'dense' (MATDENSE), 'bsr' (a python Mat of ``bsr``: block-sparse or a flat surface's dense
        pieces), matrices the block forms a panel product with, or None (step by step)."""
        from . import bsr
        if "dense" in M.getType():
            return "dense"
        return "bsr" if bsr.context(M) is not None else None

    def _blocked_history(self, n, out_u):
        blk = getattr(self, "_blk", None)
        if blk is None or not blk[0] < n <= blk[0] + self.block:
            ev = event("SSI_BEM_HistPanel")
            ev.begin()
            self._new_block(self.block * ((n - 1) // self.block))
            ev.end()
        n0, _, subs = self._blk
        i = (n - n0 - 1) // self.sub
        if i and subs[i] and self._sub_done != i:         # the first step in sub-block i (its start, or
            ev = event("SSI_BEM_HistPanel")                # where a restart resumes): its panel of the
            ev.begin()                                     # block's states before it, once
            self._panel_products(subs[i], self._R[i * self.sub:(i + 1) * self.sub], n0 + i * self.sub)
            self._sub_done = i
            ev.end()
        ev = event("SSI_BEM_HistStep")
        ev.begin()
        self._step_rest(n, out_u)
        ev.end()

    def _step_rest(self, n, out_u):
        """The block's row of step n and the terms it left to the step (in-block states, and
        matrices without a panel product). Dense and block-sparse matrices take them from every
        rank's copies of the states (one all-gather per new state, not one per product)."""
        from . import bsr
        n0, rest, _ = self._blk
        todo = rest[n - n0 - 1]
        acc = self._R[n - n0 - 1].copy()
        if any(self._panel_kind(self._mat(key, side)) for key, side in todo):
            self._replicate(n - 1)                         # the states before step n are final
        other = []
        for (key, side) in sorted(todo):
            terms = todo[(key, side)]
            M = self._mat(key, side)
            kind = self._panel_kind(M)
            if kind is None:
                other.append((key, side))
                continue
            rep = self._rep[side][2]
            x = np.zeros(rep.shape[1])
            bsr.panel_states(rep, np.zeros(len(terms), np.int64), np.array([self._rslot(m) for m, _ in terms], np.int64),
                             np.array([c for _, c in terms], float), x[None, :], False)
            if kind == "dense":
                A = M.getDenseArray(readonly=True)
                y = A @ x
                self.PETSc.Log.logFlops(2.0 * A.size)
            else:
                ctx = self._ctx(M)
                y = np.empty(acc.size)
                ctx.matvec(x, y)
                self.PETSc.Log.logFlops(ctx.flops())
            if side == "u":
                acc -= y
            else:
                acc += y
        out_u.setArray(acc)
        for (key, side) in other:                          # any other Mat type: PETSc products
            terms = todo[(key, side)]
            M = self._mat(key, side)
            if side == "u":
                self._combine(self.wu, self.ubuf, terms)
                M.mult(self.wu, self.rhs)
                out_u.axpy(-1.0, self.rhs)
            else:
                self._combine(self.wp, self.pbuf, terms)
                M.multAdd(self.wp, out_u, out_u)

    def _combine(self, w, buf, terms):
        w.set(0.0)
        w.maxpy([c for _, c in terms], [buf[self._slot(m)] for m, _ in terms])

    def step(self, correct=None):
        """Advance one step; returns (u^n, p^n) Vecs (views into the buffer). ``correct(n, x)``, if
        given, may change the solution x of the step and the known values kv_u together before they
        are stored (a linear combination with ``unit_response``s: ``bem.input_motion``)."""
        n = self.begin_step()
        self._set_known(n)
        b = self.add_known(self._b)
        self.solve(b, self.x)
        if correct is not None:
            correct(n, self.x)
        return self.store(n, self.x)

    def unit_response(self, U, x):
        """Collective: x = the unknowns of a step with zero history, zero known traction and the
        known displacement ``U`` (a Vec of the u layout, nonzero at prescribed DOFs only): the part
        of every step's solution that is linear in its known displacement. Leaves kv_u = U and
        kv_p = 0 (call before stepping, or set them again)."""
        U.copy(self.kv_u)
        self.kv_p.set(0.0)
        b = self.u_tmpl.duplicate()
        b.set(0.0)
        self.add_known(b)
        self.solve(b, x)
        b.destroy()
        return x

    def traction_of(self, x, p):
        """Collective: p = the traction of unknowns x (x at the prescribed DOFs, scattered into the
        traction layout; zero at load DOFs)."""
        p.set(0.0)
        if self.reg.n_disp:
            self.sc_x2p.scatter(x, p, addv=self.PETSc.InsertMode.INSERT_VALUES)
        return p

    # The pieces of a step, for callers that set the known values themselves
    # (the FEM-BEM coupling: u at interface nodes from the structure).
    def begin_step(self):
        """Collective: the history part of the right-hand side of step n = self.n + 1
        into ``self._b`` (it depends only on past states); returns n."""
        n = self.n + 1
        if not hasattr(self, "_b"):
            self._b = self.u_tmpl.duplicate()
        ev = event("SSI_BEM_History")
        ev.begin()
        self.history(n, self._b)
        if self.area is not None:
            self.area.add(n, self, self._b)
        ev.end()
        return n

    def add_known(self, b):
        """Collective: b += the terms of the known values in kv_u / kv_p (step matrix
        coefficients of lags 1 and 2); rows of symmetry-zero DOFs set to 0. A known vector that is zero
        on every rank (the implicit coupled step's interface displacements, a load after its end) is not
        multiplied: its terms are exact zeros (b unchanged bit for bit)."""
        # (the 2-norm: a NaN on any rank reaches every rank's sum, where MPI's MAX of the infinity norm can
        # drop it; the norms are collective, and read the Vecs' current state only once every rank has
        # released its writable view: set_known_u_owned's array is released by the caller before this)
        N2 = self.PETSc.NormType.NORM_2
        load = self.reg.n_load and not self.kv_p.norm(N2) == 0.0        # (NaN: multiplied, and seen)
        disp = self.reg.n_disp and not self.kv_u.norm(N2) == 0.0
        for lag, c in self.coefficients():
            if lag > self.L:
                continue
            if load and self.G[lag - 1] is not None:
                self.G[lag - 1].mult(self.kv_p, self.rhs)
                b.axpy(c, self.rhs)
            if disp and self.H[lag - 1] is not None:
                self.H[lag - 1].mult(self.kv_u, self.rhs)
                b.axpy(-c, self.rhs)
        if self.zero_local.size:
            b.getArray()[self.zero_local] = 0.0
        return b

    def solve(self, b, x):
        """Collective: x = A^{-1} b with the factorised step matrix."""
        ev = event("SSI_BEM_Solve")
        ev.begin()
        self._solve(b, x)
        ev.end()

    def _solve(self, b, x):
        """x = A^{-1} b: with the mirror-symmetric blocks, x = Q A'^{-1} Q^T b (``bem.mirror``)."""
        if self.mirror is None:
            self.ksp.solve(b, x)
        else:
            self.mirror.solve(self.ksp, b, x)
        reason = self.ksp.getConvergedReason()
        if reason < 0:                      # (an iterative -ssi_bem_ksp_type that stopped short: its answer is not the step's)
            names = {v: k for k, v in vars(self.PETSc.KSP.ConvergedReason).items() if isinstance(v, int)}
            kt, pt = self.ksp.getType(), self.ksp.getPC().getType()
            advice = ("the direct solve itself failed" if kt == "preonly" else
                      "leave the soil's solver to its default direct LU, or let the iterative one converge")
            raise SSIError(f"the soil's step solve did not converge at step {getattr(self, 'n', 0) + 1} "
                           f"({names.get(reason, reason)} after {self.ksp.getIterationNumber()} iterations of "
                           f"-ssi_bem_ksp_type {kt}, -ssi_bem_pc_type {pt}): {advice}")

    def solve_columns(self, m, fill, take, block=None):
        """Collective: ``petsc.solve_columns`` with the step matrix's factors (through the mirror-symmetric
        blocks' basis where they are used)."""
        solve_columns(self.ksp, self.u_tmpl, m, fill, take, block=block,
                      Q=None if self.mirror is None else self.mirror.Q)

    def store(self, n, x):
        """Collective: u^n, p^n into the history buffers from the unknowns x (u at
        free DOFs, p at prescribed-displacement DOFs) and the known values kv_u,
        kv_p; returns (u, p) and makes n the current step."""
        self.n = n
        u = self.ubuf[self._slot(n)]
        p = self.pbuf[self._slot(n)]
        # u: solution at free DOFs, known values at prescribed DOFs
        x.copy(u)
        p.set(0.0)
        if self.reg.n_disp:
            self.sc_x2p.scatter(x, p, addv=self.PETSc.InsertMode.INSERT_VALUES)
            uk = u.getArray()
            r0 = u.getOwnershipRange()[0]
            loc = self.dofs_pres_local(r0, len(uk))
            if loc.size:
                uk[loc] = self.kv_u.getArray()[loc]
        p.axpy(1.0, self.kv_p)
        return u, p

    # ------------------------------------------------------------ checkpoint
    def _kept_steps(self):
        """The steps whose states the ring buffer still holds (all the history sum can read)."""
        return range(max(1, self.n - self.depth + 1), self.n + 1)

    RING_BLOCK = 64      # states per checkpoint dataset: one collective HDF5 write per 64 steps, not per step

    def checkpoint_vecs(self):
        """{name: Vec}: the states u^m, p^m the next steps read (``io.checkpoint``), packed
        ``RING_BLOCK`` steps to a Vec: ``bem_u_ring_BBB`` has block size k (the steps of block BBB,
        oldest first) and is written as one (N, k) dataset in global row order, so any rank count
        reads it back. One dataset per step cost 17 to 40 ms each in the PETSc HDF5 viewer (1.1 s
        for the 62 of the coupled case of tests/test_checkpoint.py at -n 2), more than the 1 s
        mpirun leaves between SIGTERM and SIGKILL; packed, the same checkpoint takes ~0.1 s."""
        out = {}
        steps = list(self._kept_steps())
        for name, buf, tmpl in (("u", self.ubuf, self.u_tmpl),
                                ("p", self.pbuf, self.p_tmpl)):
            if not tmpl.getSize():
                continue
            for b in range(0, len(steps), self.RING_BLOCK):
                blk = steps[b:b + self.RING_BLOCK]
                v = self._ring_vec(buf[0], len(blk))
                a = v.getArray().reshape(-1, len(blk))
                for j, m in enumerate(blk):
                    a[:, j] = buf[self._slot(m)].getArray(readonly=True)
                out[f"bem_{name}_ring_{b // self.RING_BLOCK:03d}"] = v
        return out

    def _ring_vec(self, like, k):
        """A Vec of k states per owned row of ``like`` (block size k)."""
        return self.PETSc.Vec().createMPI((like.getLocalSize() * k, like.getSize() * k), bsize=k, comm=like.getComm())

    def restore(self, reader, n):
        """Collective: the states of a checkpoint after step n (``checkpoint_vecs``; a checkpoint
        of an older version holds one dataset per step, ``bem_u_000123``)."""
        self.n = int(n)
        self._blk = self._rep = None
        for side in self.toeplitz:
            side.reset()                    # its kept transforms are made again from the restored states
        steps = list(self._kept_steps())
        for name, buf, tmpl in (("u", self.ubuf, self.u_tmpl), ("p", self.pbuf, self.p_tmpl)):
            if not tmpl.getSize():
                continue
            if reader.has(f"bem_{name}_ring_000"):
                for b in range(0, len(steps), self.RING_BLOCK):
                    blk = steps[b:b + self.RING_BLOCK]
                    v = reader.load(f"bem_{name}_ring_{b // self.RING_BLOCK:03d}", self._ring_vec(buf[0], len(blk)))
                    a = v.getArray(readonly=True).reshape(-1, len(blk))
                    for j, m in enumerate(blk):
                        buf[self._slot(m)].getArray()[:] = a[:, j]
                    v.destroy()
            else:
                for m in steps:
                    reader.load(f"bem_{name}_{m:06d}", buf[self._slot(m)])

    def dofs_pres_local(self, r0, nloc):
        if not hasattr(self, "_pres_local"):
            d = np.where(np.repeat(self.pres, 3))[0]
            self._pres_local = (d[(d >= r0) & (d < r0 + nloc)] - r0).astype(np.int64)
        return self._pres_local
