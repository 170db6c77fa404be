r"""The step matrix's mirror symmetries (``-ssi_step_mirror``): one LU of independent blocks.

A soil surface whose nodes, prescribed-displacement nodes and traction unknowns map onto themselves under
the reflection x -> 2 c_x - x (and/or y -> 2 c_y - y) has a step matrix A that commutes with it: R A = A R,
R the DOFs' signed permutation (node n -> its mirror, the reflected displacement or traction component's
sign flipped). The group G of the reflections (2 or 4 elements) then splits the DOFs into |G| invariant
subspaces, one per character sigma (sigma(g) = +-1: symmetric or antisymmetric about each plane), spanned by
the orthonormal columns of Q (3 N x 3 N, at most |G| nonzeros a row):

    q_{sigma,o,c} = sum_g sigma(g) s_g(c) e_{g(n_o), c} / norm      (n_o the orbit o's representative node)

and Q^T A Q = diag(A_sigma) is block diagonal. Each step's solve is x = Q A'^{-1} Q^T b with A' = diag(A_sigma)
factorised once: MUMPS's ordering finds the blocks, and the top separators along the mirror lines, the
largest fronts of a grid's nested dissection, are gone (the paper's building on the uniform 72 m grid: 50.3 M
entries in the factors against 77.6 M, a step's solve 29 ms against 45: jobscripts/step_mirror_check.sh).

A' is folded from the representatives' rows of A (``fold``, compiled): row (sigma, o, c) of A' is row
(n_o, c) of A Q_sigma over q_{sigma,o,c}(n_o, c), exact when A commutes with G. A computed A commutes to
round-off only: on a flat surface the self blocks' in-plane/normal entries, zero by symmetry, come out of
the singular integration at round-off level, which the reflection maps to their negatives. So the commutation is checked before (``commutation_defect``: A R v against R A v on a fixed vector, to
``TOL`` of A v), the factors' solve against A itself after (``Marcher._test_residual``, at most
``march.BLR_TOL``, or 100 eps with a block low-rank precision the user chose), and each step's residual
check (``bem_residual``) uses A, not the folded blocks; a check that fails puts A's own LU back, said in one
line. The blocks are tried for a direct solve only (the ssi_bem_ KSP preonly with an LU or Cholesky), never
with symmetry planes (the model is already reduced); the interface columns' region (``coupling.columns``) goes
through its own blocks, checked the same way against its own matrix.
"""
import numpy as np
from numba import njit

# the largest commutation defect ||A R v - R A v||_inf / ||A v||_inf accepted: the step equations' round-off (4e-13
# on the paper's building on the uniform 72 m grid, whose blocks' test residual is then 1.8e-13; 3.4e-12 on
# today's graded 36 m grid, where the blocks left 1.2e-12 > march.BLR_TOL: refused before factorising; a
# surface that is not symmetric gives order 1)
TOL = 1e-12


def reflections(X, pres, tnodes, tol=1e-9):
    """[(axis, centre, node map)] of the reflections about x = c and y = c (c the mid-point of the nodes'
    extent) that map the nodes ``X`` (N, 3) onto themselves (within ``tol`` of the extent), the prescribed
    nodes (``pres``, bool N) onto prescribed nodes and the traction unknowns' nodes (``tnodes``) onto
    themselves."""
    from scipy.spatial import cKDTree
    X = np.asarray(X, float)
    N = len(X)
    if N == 0:
        return []
    ext = float(np.ptp(X[:, :2], axis=0).max()) or 1.0
    tree = cKDTree(X)
    tmask = np.zeros(N, bool)
    tmask[np.asarray(tnodes, np.int64)] = True
    out = []
    for axis in (0, 1):
        c = 0.5 * (X[:, axis].min() + X[:, axis].max())
        Y = X.copy()
        Y[:, axis] = 2.0 * c - Y[:, axis]
        d, j = tree.query(Y)
        if d.max() > tol * ext or not np.array_equal(j[j], np.arange(N)):
            continue
        if np.array_equal(pres[j], pres) and np.array_equal(tmask[j], tmask):
            out.append((axis, c, j.astype(np.int64)))
    return out


def surface_reflections(prob, nodes=None):
    """``reflections`` of the soil surface of ``prob`` (a HalfSpace) from its nodes and regions alone, or of its
    nodes ``nodes`` (a subset: the interface columns' region, ``coupling.columns``); none with symmetry planes
    (the model is already reduced)."""
    reg = prob.regions
    N = prob.mesh.n_nodes
    pres = np.zeros(N, bool)
    pres[np.asarray(reg.disp_nodes, np.int64)] = True
    tn = np.asarray(reg.tnode)[reg.n_load:] if reg.n_t else np.zeros(0, np.int64)
    if getattr(prob, "planes", None):
        return []
    if nodes is None:
        return reflections(prob.mesh.nodes, pres, tn)
    where = -np.ones(N, np.int64)
    where[nodes] = np.arange(len(nodes))
    t = where[np.asarray(tn, np.int64)]
    return reflections(prob.mesh.nodes[nodes], pres[nodes], t[t >= 0])


def blocks_of(prob):
    """The number of independent blocks the step matrix of ``prob`` (a HalfSpace) would split into (1, 2 or 4),
    from its nodes and regions alone (``surface_reflections``; the commutation, which only the matrix can show,
    assumed: ``petsc-ssi estimate``)."""
    return 1 << len(surface_reflections(prob))


def group(refl):
    """(maps (|G|, N) node maps, signs (|G|, 3) component signs, chars (|G|, |G|) sigma(g) per character
    row) of the group the reflections generate (generators' products in binary order)."""
    N = len(refl[0][2])
    k = len(refl)
    maps, signs = [], []
    for bits in range(1 << k):
        m = np.arange(N)
        s = np.ones(3)
        for i in range(k):
            if bits >> i & 1:
                m = refl[i][2][m]
                s[refl[i][0]] *= -1.0
        maps.append(m)
        signs.append(s)
    chars = np.array([[(-1.0) ** bin(sig & g).count("1") for g in range(1 << k)] for sig in range(1 << k)])
    return np.array(maps), np.array(signs), chars


def basis(maps, signs, chars):
    """The columns of Q: (dof (3 N), sigma) arrays ``col`` (column of Q in the folded numbering, -1: none)
    and ``val`` (Q's entry), the columns' representative DOFs ``rep_dof`` (in column order) and block
    ``sigma`` of each column. Representatives: an orbit's smallest node if that is even, else its largest
    (the same for any rank count; about half the orbits' on each side of a mirror line)."""
    nG, N = maps.shape
    lo = maps.min(axis=0)
    hi = maps.max(axis=0)
    rep_of = np.where(lo % 2 == 0, lo, hi)                 # (node -> its orbit's representative)
    reps = np.flatnonzero(rep_of == np.arange(N))
    col = -np.ones((3 * N, nG), np.int64)
    val = np.zeros((3 * N, nG))
    T = maps[:, reps]                                        # (g, rep): g(rep)
    same = T[:, None, :] == T[None, :, :]                    # (g, g', rep)
    first = ~np.any(np.tril(np.ones((nG, nG), bool), -1)[:, :, None] & same, axis=1)   # g the first for its node
    cols_by = {}
    for sig in range(nG):
        for c in range(3):
            w = chars[sig][:, None] * signs[:, c][:, None]                 # (g, 1): sigma(g) s_g(c)
            coef = np.einsum("ghr,h->gr", same, w[:, 0])                   # summed over g' with g'(rep) = g(rep)
            coef = np.where(first, coef, 0.0)
            nrm = np.sqrt((coef ** 2).sum(axis=0))
            ok = nrm > 0.5
            cols_by[(sig, c)] = (ok, coef[:, ok] / nrm[ok])
    # numbering: representative by representative (node order), then sigma, then component
    order = []
    for sig in range(nG):
        for c in range(3):
            ok, _ = cols_by[(sig, c)]
            order.append((sig, c, np.flatnonzero(ok)))
    key_rep = np.concatenate([reps[i] for _, _, i in order])
    key_sig = np.concatenate([np.full(i.size, s) for s, _, i in order])
    key_c = np.concatenate([np.full(i.size, c) for _, c, i in order])
    perm = np.lexsort((key_c, key_sig, key_rep))
    colno = np.empty(perm.size, np.int64)
    colno[perm] = np.arange(perm.size)
    pos = 0
    for sig, c, idx in order:
        _, q = cols_by[(sig, c)]
        ids = colno[pos:pos + idx.size]
        pos += idx.size
        for g in range(nG):
            nz = q[g] != 0.0
            dof = 3 * T[g, idx[nz]] + c
            col[dof, sig] = ids[nz]
            val[dof, sig] = q[g, nz]
    return col, val, (3 * key_rep + key_c)[perm], key_sig[perm]


@njit(cache=True)
def fold(ip, jj, aa, r0, k0, src, sig, col, val):
    """Rows of A' = Q^T A Q from A's rows (local CSR ``ip``, ``jj`` global columns, ``aa``; first row ``r0``):
    row k of the output is A's row ``src[k]`` (global DOF, local to this rank) times Q_sigma (sigma =
    ``sig[k]``: column j of A goes to ``col[j, sigma]`` with weight ``val[j, sigma]``) over Q's entry at the
    row's own DOF; duplicate columns summed, columns ascending, exact zeros left out except the diagonal
    (output row k is A' row ``k0 + k``). Returns (indptr, indices, data)."""
    nk = src.size
    tot = 0
    for k in range(nk):
        r = src[k] - r0
        tot += ip[r + 1] - ip[r]
    indptr = np.zeros(nk + 1, np.int64)
    indices = np.empty(tot, np.int64)
    data = np.empty(tot)
    n = 0
    for k in range(nk):
        r = src[k] - r0
        s = sig[k]
        scale = 1.0 / val[src[k], s]
        a, e = ip[r], ip[r + 1]
        cs = np.empty(e - a, np.int64)
        vs = np.empty(e - a)
        m = 0
        for t in range(a, e):
            j = jj[t]
            cj = col[j, s]
            if cj >= 0:
                cs[m] = cj
                vs[m] = aa[t] * val[j, s] * scale
                m += 1
        o = np.argsort(cs[:m], kind="mergesort")
        last = -1
        for i in range(m):
            c = cs[o[i]]
            if c != last:
                indices[n] = c
                data[n] = vs[o[i]]
                n += 1
                last = c
            else:
                data[n - 1] += vs[o[i]]
        # (exact zeros out, the diagonal kept)
        w = indptr[k]
        for i in range(indptr[k], n):
            if data[i] != 0.0 or indices[i] == k0 + k:
                indices[w] = indices[i]
                data[w] = data[i]
                w += 1
        n = w
        indptr[k + 1] = n
    return indptr, indices[:n].copy(), data[:n].copy()


def solve_residual(A, solve, zero_local=()):
    """Collective: ||A x - b|| / ||b|| of ``solve(b, x)`` on the fixed right-hand side b_i = sin(0.7 i + 0.3)
    over the global rows (zero at ``zero_local``, this rank's symmetry-zero rows): the check of a factorised
    step matrix (``Marcher._test_residual``: block low-rank, the blocks) and of the region's blocks."""
    b = A.createVecLeft()
    r0, r1 = b.getOwnershipRange()
    b.getArray()[:] = np.sin(0.7 * np.arange(r0, r1) + 0.3)
    if len(zero_local):
        b.getArray()[zero_local] = 0.0
    x, r = b.duplicate(), b.duplicate()
    solve(b, x)
    A.mult(x, r)
    r.axpy(-1.0, b)
    res = r.norm() / b.norm()
    for v in (b, x, r):
        v.destroy()
    return res


def signed_permutation(PETSc, comm, nmap, sign, r0, r1):
    """The reflection's DOF map as an AIJ Mat (rows r0..r1 of 3 N): (R v)(n, c) = s(c) v(m(n), c)."""
    d = np.arange(r0, r1)
    cols = 3 * nmap[d // 3] + d % 3
    n = 3 * len(nmap)
    return PETSc.Mat().createAIJ(size=((r1 - r0, n), (r1 - r0, n)), comm=comm,
                                 csr=(np.arange(r1 - r0 + 1).astype(PETSc.IntType), cols.astype(PETSc.IntType),
                                      sign[d % 3].astype(float)))


def commutation_defect(PETSc, comm, A, refl):
    """Collective: max over the reflections of ||A R v - R A v||_inf / ||A v||_inf, v_j = sin(0.7 j + 0.3) over
    the global DOFs (``permutation_defect`` of their signed permutations)."""
    r0, r1 = A.getOwnershipRange()
    Rs = []
    for axis, _, nmap in refl:
        s = np.ones(3)
        s[axis] = -1.0
        Rs.append(signed_permutation(PETSc, comm, nmap, s, r0, r1))
    try:
        return permutation_defect(PETSc, A, Rs)
    finally:
        for R in Rs:
            R.destroy()


def permutation_defect(PETSc, A, Rs):
    """Collective: max over the signed permutations ``Rs`` (Mats) of ||A R v - R A v||_inf / ||A v||_inf,
    v_j = sin(0.7 j + 0.3) over A's global rows (the step matrix's reflections here; the interface region's
    in ``coupling.columns``)."""
    r0, r1 = A.getOwnershipRange()
    v = A.createVecRight()
    v.getArray()[:] = np.sin(0.7 * np.arange(r0, r1) + 0.3)
    Av, Rv, ARv, RAv = v.duplicate(), v.duplicate(), v.duplicate(), v.duplicate()
    A.mult(v, Av)
    size = max(Av.norm(PETSc.NormType.INFINITY), 1e-300)
    worst = 0.0
    for R in Rs:
        R.mult(v, Rv)
        A.mult(Rv, ARv)
        R.mult(Av, RAv)
        ARv.axpy(-1.0, RAv)
        worst = max(worst, ARv.norm(PETSc.NormType.INFINITY) / size)
    for o in (v, Av, Rv, ARv, RAv):
        o.destroy()
    return worst


class MirrorBlocks:
    """Collective: the step matrix A's mirror-symmetric form, or why not (``why``: '' when built). ``Q`` (AIJ:
    A's rows, the blocks' columns), ``Ap`` = Q^T A Q (AIJ, block diagonal), ``sizes`` the blocks' DOFs,
    ``planes`` e.g. 'x = 0 and y = 0', ``defect`` the commutation check's value, ``refl`` the reflections
    (``reflections``)."""

    def __init__(self, PETSc, comm, A, X, pres, tnodes):
        self.Q = self.Ap = None
        self.defect = float("nan")
        refl = self.refl = reflections(X, pres, tnodes)
        if not refl:
            self.why = "the surface, its prescribed-displacement or traction nodes are not mirror-symmetric"
            return
        self.planes = " and ".join(f"{'xy'[a]} = {c:.6g}" for a, c, _ in refl)
        r0, r1 = A.getOwnershipRange()
        from mpi4py import MPI
        if not comm.tompi4py().allreduce(int(r0 % 3 == 0 and r1 % 3 == 0), op=MPI.MIN):
            self.why = "the step matrix's rows are not whole nodes on every rank"     # (the blocks' rows assume it)
            return
        self.defect = commutation_defect(PETSc, comm, A, refl)
        if not self.defect <= TOL:
            self.why = (f"the nodes mirror about {self.planes} but the step matrix does not commute with the "
                        f"reflection (defect {self.defect:.2g} > {TOL:g})")
            return
        maps, signs, chars = group(refl)
        col, val, rep_dof, sig_of = basis(maps, signs, chars)
        n = A.getSize()[0]
        if rep_dof.size != n:                    # (cannot happen: Q is square and orthogonal)
            self.why = f"the symmetric basis has {rep_dof.size} columns for {n} DOFs"
            return
        own = (rep_dof >= r0) & (rep_dof < r1)
        k = np.flatnonzero(own)
        k0, k1 = (int(k[0]), int(k[-1]) + 1) if k.size else (int(np.count_nonzero(rep_dof < r0)),) * 2
        ip, jj, aa = A.getValuesCSR()
        iP, iJ, dA = fold(np.asarray(ip, np.int64), np.asarray(jj, np.int64), np.asarray(aa, float), r0, k0,
                          rep_dof[k0:k1].astype(np.int64), sig_of[k0:k1].astype(np.int64), col, val)
        IT = PETSc.IntType
        self.Ap = PETSc.Mat().createAIJ(size=((k1 - k0, n), (k1 - k0, n)), comm=comm,
                                        csr=(iP.astype(IT), iJ.astype(IT), dA))
        self.Ap.assemble()
        cl, vl = col[r0:r1], val[r0:r1]
        nzr = cl >= 0
        o = np.argsort(np.where(nzr, cl, np.iinfo(np.int64).max), axis=1, kind="stable")
        cs = np.take_along_axis(cl, o, axis=1)
        vs = np.take_along_axis(vl, o, axis=1)
        m = cs >= 0
        qp = np.r_[0, np.cumsum(m.sum(axis=1))]
        self.Q = PETSc.Mat().createAIJ(size=((r1 - r0, n), (k1 - k0, n)), comm=comm,
                                       csr=(qp.astype(IT), cs[m].astype(IT), vs[m]))
        self.Q.assemble()
        self.sizes = [int(np.count_nonzero(sig_of == s)) for s in range(len(chars))]
        self.why = ""

    def solve(self, ksp, b, x):
        """x = Q Ap^-1 Q^T b, ``ksp`` the factorised blocks (its work vectors made at the first call)."""
        if getattr(self, "_y", None) is None:
            self._y = (self.Ap.createVecRight(), self.Ap.createVecRight())
        yb, yx = self._y
        self.Q.multTranspose(b, yb)
        ksp.solve(yb, yx)
        self.Q.mult(yx, x)

    def destroy(self):
        for M in (self.Q, self.Ap) + tuple(getattr(self, "_y", None) or ()):
            if M is not None:
                M.destroy()
        self._y = None
