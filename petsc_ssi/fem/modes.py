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
mode number and attribute ``frequencies_hz``; the modal participation (``participation``:
effective masses per direction, their cumulative share, effective heights) in the group
``modal_participation`` and the log. With -ssi_fem_damping_ratio
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
    eps.setDimensions(nev=min(n_modes + max(4, n_modes // 2), Kf.getSize()[0]))
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




DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")


def participation(shapes, model, comm):
    """Collective: modal participation of the mode shapes (issue 43, item 2), a dict of arrays (every
    rank; ``modal_participation_group`` gives them units):

      influence vectors   r_d (d = x, y, z: unit translations; rx, ry, rz: unit rotations about the
                          base point x_b, rotation dofs included), zero on the fixed dofs;
      L[k, d] = phi_k^T M r_d,  Mn[k] = phi_k^T M phi_k (the shapes as written, max |u| = 1),
      participation_factor Gamma = L / Mn, effective_mass M*_kd = L^2 / Mn, and its share of the
      total M_d = r_d^T M r_d (the mass that moves with the base: the free dofs' mass; for rotations
      the mass moment of inertia about x_b). sum_k M*_kd = M_d over ALL modes (M-orthogonality).
      effective_height h*_k (x, y) = the height above the base of the resultant of mode k's inertia
      forces under that ground motion: the overturning moment about the base over the base shear,
      h*_x = L[k, ry] / L[k, x], h*_y = -L[k, rx] / L[k, y] (Chopra's L^theta / L^h for a shear
      building; NaN where the mode has no share along that direction).
    x_b: the centroid of the fixed nodes at their lowest level (the lowest node's level for a free
    structure)."""
    from mpi4py import MPI
    dm, coords = model.dofmap, model.mesh.coords
    fixed = np.asarray(model.fixed, np.int64)
    fnodes = None
    if fixed.size:                                 # the node of each fixed dof (offsets: each node's first dof)
        off = np.asarray(dm.offset[:dm.n_nodes], np.int64)
        order = np.argsort(off, kind="stable")
        fnodes = np.unique(order[np.searchsorted(off[order], fixed, side="right") - 1])
    zb = float(coords[fnodes, 2].min()) if fnodes is not None and fnodes.size else float(coords[:, 2].min())
    base = coords[fnodes] if fnodes is not None and fnodes.size else coords
    at = np.abs(base[:, 2] - zb) <= 1e-9 * max(float(np.ptp(coords)), 1.0)
    xb = np.r_[base[at, :2].mean(axis=0), zb]
    R = dm.rigid_body_modes(coords, centre=xb)
    R[fixed] = 0.0
    r0, r1 = dm.r0, dm.r1
    Rl = R[r0:r1]
    m = model.m.getArray(readonly=True)
    mpi = comm.tompi4py()
    loc = np.zeros((len(shapes) + 1, 6))
    mn = np.zeros(len(shapes))
    for k, s in enumerate(shapes):
        phi = s.getArray(readonly=True)
        loc[k] = (m * phi) @ Rl
        mn[k] = float((m * phi) @ phi)
    loc[-1] = ((m[:, None] * Rl) * Rl).sum(axis=0)
    L = np.zeros_like(loc)
    mpi.Allreduce(loc, L, op=MPI.SUM)
    Mn = np.zeros_like(mn)
    mpi.Allreduce(mn, Mn, op=MPI.SUM)
    total = L[-1]
    L = L[:-1]
    Mn_safe = np.where(Mn > 0, Mn, np.inf)
    gamma = L / Mn_safe[:, None]
    meff = L ** 2 / Mn_safe[:, None]
    share = np.where(total > 0, meff / np.where(total > 0, total, 1.0), np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        small = lambda a, d: np.abs(a) <= 1e-9 * np.sqrt(np.maximum(total[d], 1e-300) * Mn)   # noqa: E731
        hx = np.where(small(L[:, 0], 0), np.nan, L[:, 4] / L[:, 0])
        hy = np.where(small(L[:, 1], 1), np.nan, -L[:, 3] / L[:, 1])
    return {"L": L, "modal_mass": Mn, "participation_factor": gamma, "effective_mass": meff,
            "total_mass": total, "effective_mass_ratio": share, "cumulative_mass_ratio": np.cumsum(share, axis=0),
            "effective_height": np.c_[hx, hy], "base_point": xb}


def modes_for(cum, share=0.9):
    """Per direction: the number of modes whose cumulative effective mass reaches ``share`` (0 when
    the computed modes do not reach it)."""
    out = []
    for d in range(cum.shape[1]):
        hit = np.flatnonzero(cum[:, d] >= share - 1e-12)
        out.append(int(hit[0]) + 1 if hit.size else 0)
    return np.array(out)


def modal_participation_group(p, freqs):
    """The output group 'modal_participation' {name: (array, unit, attrs)} of ``participation``."""
    dirs = ", ".join(DIRECTIONS)
    units6 = "kg (x, y, z), kg m^2 (rx, ry, rz)"
    return {
        "frequency": (np.asarray(freqs, float), "Hz", {"convention": "natural frequency of each mode"}),
        "directions": (np.array([d.encode() for d in DIRECTIONS]), "1", {"convention": "the columns of the "
                       "(modes, 6) datasets: translations x, y, z and rotations about the base point"}),
        "modal_mass": (p["modal_mass"], "kg (shapes with max |u| = 1)", {"convention": "phi^T M phi"}),
        "participation_factor": (p["participation_factor"], "1 (x, y, z), m (rx, ry, rz)",
                                 {"convention": "Gamma = phi^T M r / phi^T M phi, columns " + dirs}),
        "effective_mass": (p["effective_mass"], units6, {"convention": "effective modal mass (phi^T M r)^2 / "
                           "phi^T M phi per direction " + dirs + "; summed over all modes it is total_mass"}),
        "total_mass": (p["total_mass"], units6, {"convention": "r^T M r: the mass (moment of inertia about the "
                       "base point) that moves with the base: the free dofs'"}),
        "effective_mass_ratio": (p["effective_mass_ratio"], "1", {"convention": "effective_mass / total_mass"}),
        "cumulative_mass_ratio": (p["cumulative_mass_ratio"], "1", {"convention": "sum of effective_mass_ratio "
                                  "over modes 1..k"}),
        "modes_for_90_percent": (modes_for(p["cumulative_mass_ratio"]), "1", {"convention": "the number of modes "
                                 "whose cumulative effective mass reaches 90 % per direction (0: not reached "
                                 "with the modes computed; ask for more with -ssi_modes_n)"}),
        "effective_height": (p["effective_height"], "m", {"convention": "height above the base of the resultant "
                             "of the mode's inertia forces under ground motion along x, y: base overturning moment "
                             "/ base shear (Chopra's h*_n = L^theta / L^h); NaN without a share along it"}),
        "base_point": (p["base_point"], "m", {"convention": "the base point (the fixed nodes' centroid at their "
                       "lowest level) of the rotations and heights"}),
    }
