"""``petsc-ssi modes``: natural frequencies and mode shapes (SLEPc).

Generalised symmetric problem K x = omega^2 M x (lumped M) on the free dofs
(fixed dofs removed with a sub-matrix; with no -ssi_fem_fixed the structure
is free and its six rigid-body modes come out at 0 Hz), solved by Krylov-
Schur with shift-and-invert about a small negative target (so that K - sigma M
is positive definite even for a free structure; every eigenvalue is >= 0 >
sigma, so "nearest the target" means "lowest"). The inner solve is a direct
factorisation chosen by ``petsc.direct_solver_defaults`` (MUMPS, else
SuperLU_dist; PETSc's serial LU only on one rank, with a warning; an error in
parallel without either). Options prefix ``ssi_modes_`` (``-ssi_modes_eps_nev`` is set
to -ssi_modes_n plus max(4, n/2) spares; any ``-ssi_modes_eps_*``/``-ssi_modes_st_*`` wins).

Krylov methods can miss one copy of a multiple eigenvalue, and symmetric
structures have many. The result is checked by Sylvester's law of inertia:
the negative pivots of an LDL^T factorisation of K - sigma M (MUMPS), with
sigma in the first gap above the reported modes, count the eigenvalues below
sigma; if SLEPc found fewer, it solves again with twice the nev.

Output: a table ``mode,frequency_hz`` on stdout (rank 0), the mode shapes
(max |u| = 1) as snapshots ``mode_shape_<k>`` of -ssi_output with "time" =
mode number and attribute ``frequencies_hz``. With -ssi_fem_damping_ratio
zeta, alpha_m = 2 zeta omega is printed for the first flexible mode.
"""
import math

import numpy as np

from ..petsc import init, collective_error, printf, set_default_options, direct_solver_defaults
from ..monitor import event
from .assembly import diagonal_mat, owned_dofs


def _submatrices(K, m, fixed):
    """Collective: K and diag(m) restricted to the free dofs, and their IS."""
    PETSc = init()
    comm = K.getComm()
    r0, r1 = K.getOwnershipRange()
    free = np.setdiff1d(np.arange(r0, r1), owned_dofs(fixed, K)).astype(PETSc.IntType)
    isf = PETSc.IS().createGeneral(free, comm=comm)
    Kf = K.createSubMatrix(isf, isf)
    mf = m.getSubVector(isf)
    Mf = diagonal_mat(mf)
    m.restoreSubVector(isf, mf)
    return Kf, Mf, isf, free


def default_target(mat, coords):
    """-1e-3 (c_s / L)^2: a negative shift well below the lowest flexible omega^2 of a solid.
    ``mat``: a Material, or a Model (then the smallest diagonal ratio K_ii / M_ii over the
    translations replaces c_s^2 / L^2, which suits frames and shells too)."""
    if hasattr(mat, "K") and mat.K is not None:
        return -1e-6 * _min_diag_ratio(mat)
    L = float(np.max(np.ptp(coords, axis=0)))
    cs2 = mat.E / (2 * (1 + mat.nu)) / mat.rho
    return -1e-3 * cs2 / L ** 2


def _min_diag_ratio(model):
    """Collective: min over free dofs of K_ii / M_ii."""
    d = model.K.getDiagonal()
    a = d.getArray(readonly=True) / np.maximum(model.m.getArray(readonly=True), 1e-300)
    free = np.ones(a.size, bool)
    free[owned_dofs(model.fixed, model.K) - model.K.getOwnershipRange()[0]] = False
    a = a[free & (a > 0)]
    from mpi4py import MPI
    v = model.K.getComm().tompi4py().allreduce(float(a.min()) if a.size else np.inf, op=MPI.MIN)
    d.destroy()
    return v if np.isfinite(v) else 1.0


def count_below(Kf, Mf, sigma):
    """Collective: the number of eigenvalues of K x = lambda M x below sigma (Sylvester's law of inertia:
    the negative pivots of the LDL^T factor of K - sigma M, MUMPS INFOG(12), ICNTL(13) = 1 so that a
    ScaLAPACK root node is counted too), or None when PETSc has no MUMPS."""
    PETSc = init()
    from ..petsc import has_package
    if not has_package("mumps"):
        return None
    A = Kf.copy()
    A.axpy(-sigma, Mf, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
    A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    ksp = PETSc.KSP().create(Kf.getComm())
    ksp.setOperators(A)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("cholesky")
    pc.setFactorSolverType("mumps")
    pc.setFactorSetUpSolverType()
    F = pc.getFactorMatrix()
    F.setMumpsIcntl(13, 1)
    ksp.setUp()
    n = int(F.getMumpsInfog(12))
    ksp.destroy()
    A.destroy()
    return n


def _check_sigma(lam, n_modes):
    """(sigma, expected count): a shift in the first clear gap of the sorted converged eigenvalues at or
    after the n-th, so that an unconverged copy of a multiple eigenvalue cannot straddle it."""
    scale = max(float(np.abs(lam).max()), 1e-300)
    for j in range(n_modes, len(lam)):
        if lam[j] - lam[j - 1] > 1e-6 * scale:
            return 0.5 * (lam[j - 1] + lam[j]), j
    return lam[-1] + 1e-6 * scale, len(lam)


def compute_modes(K, m, fixed, n_modes, target, prefix="ssi_modes_", max_attempts=4):
    """Collective: (frequencies [Hz] (k,), list of full-size mode Vecs (max |u| = 1)).

    Krylov methods can miss one copy of a multiple eigenvalue (symmetric structures have many). Extra
    eigenpairs are requested (nev = n + max(4, n/2)), and the result is checked by an inertia count of
    K - sigma M with sigma just above the reported modes: if fewer eigenvalues were found than lie below
    sigma, the solve is repeated with twice as many, and a clear error follows after ``max_attempts``."""
    PETSc = init()
    from slepc4py import SLEPc
    comm = K.getComm()
    Kf, Mf, isf, free = _submatrices(K, m, fixed)
    defaults = {"st_type": "sinvert"}
    defaults.update({"st_" + k: v for k, v in direct_solver_defaults(comm).items()})
    set_default_options(prefix, defaults, log=None)
    eps = SLEPc.EPS().create(comm)
    eps.setOptionsPrefix(prefix)
    eps.setOperators(Kf, Mf)
    eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
    eps.setDimensions(nev=n_modes + max(4, n_modes // 2))
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
    eps.setTarget(target)
    eps.setTolerances(tol=1e-10)
    eps.setFromOptions()
    ndof = Kf.getSize()[0]
    for attempt in range(1, max_attempts + 1):
        with event("FEM_modes"):
            eps.solve()
        nconv = eps.getConverged()
        collective_error(None if nconv >= n_modes else f"SLEPc converged {nconv} of {n_modes} modes", comm)
        lam_all = np.array([eps.getEigenvalue(i).real for i in range(nconv)])
        order = np.argsort(lam_all)
        lam = lam_all[order]
        sigma, expected = _check_sigma(lam, n_modes)
        with event("FEM_modes_inertia"):
            below = count_below(Kf, Mf, sigma)
        if below is None or below == expected:
            if below is not None:
                printf(f"[modes] inertia check: {below} eigenvalues below {sigma:.6g} rad^2/s^2, all found")
            break
        nev = eps.getDimensions()[0]
        collective_error(None if below > expected and attempt < max_attempts and nev < ndof else
                         f"SLEPc found {expected} eigenvalues below {sigma:.6g} rad^2/s^2 but the inertia of "
                         f"K - sigma M counts {below} (after {attempt} solves, nev = {nev}); "
                         f"try -{prefix}eps_nev/-{prefix}eps_ncv larger", comm)
        printf(f"[modes] inertia check: {below} eigenvalues below {sigma:.6g} rad^2/s^2, {expected} found; "
               f"solving again with nev = {min(2 * nev, ndof)}")
        eps.setDimensions(nev=min(2 * nev, ndof), ncv=PETSc.DECIDE)
    xr = Kf.createVecRight()
    freqs, shapes = [], []
    for i in order[:n_modes]:
        eps.getEigenvector(int(i), xr)
        full = m.duplicate()
        full.zeroEntries()
        full.getArray()[free - K.getOwnershipRange()[0]] = xr.getArray(readonly=True)
        full.scale(1.0 / max(full.norm(PETSc.NormType.INFINITY), 1e-300))
        freqs.append(math.sqrt(max(lam_all[i], 0.0)) / (2 * math.pi))
        shapes.append(full)
    for obj in (eps, Kf, Mf, isf, xr):
        obj.destroy()
    return np.array(freqs), shapes


