"""Hex8 element matrices and the distributed stiffness K and lumped mass M.

Element kernels (vectorised over elements with numpy einsum, 2x2x2 Gauss):
  K_e[a i, b j] = int  lambda N_a,i N_b,j + mu (N_a,j N_b,i + delta_ij N_a,k N_b,k) dV
  m_a           = rho int N_a dV            (row sum of the consistent mass;
                                             positive for trilinear bricks)
``hex8_stiffness_reference`` is the slow textbook B^T D B version the fast
kernel is tested against.

Parallel layout (``Layout``): node-blocked, bs 3, dof 3*node + component; rank
r owns the nodes [n0, n1) of PETSc's split. Each rank computes the element
matrices of every brick that touches one of its nodes, keeps the rows it
owns, sums them into a local CSR (global columns) that also gives the exact
preallocation, and adds them with ``setValuesCSR(..., ADD_VALUES)``. No
matrix is ever assembled serially and scattered. M is stored as a Vec (the
diagonal): D = K + c M adds it to K's diagonal, and ``diagonal_mat`` makes
the diagonal AIJ that SLEPc needs (modes.py, on the free dofs). C = alpha_m M
(paper, below eq. 15) is never formed.

Fixed dofs (one implementation for the integrators, the static solve and the
modes): ``owned_dofs`` picks the fixed dofs a rank owns, ``eliminate_dofs``
zeroes their rows and columns and puts the mean diagonal on the diagonal
(rows scaled like the rest, for AMG).
"""
from dataclasses import dataclass

import numpy as np

from ..petsc import init, SSIError, collective_error
from ..monitor import event
from .mesh import one_line

XI_NODES = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                     [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)


def gauss_hex(order=2):
    """Tensor Gauss-Legendre points (G, 3) and weights (G,) on [-1, 1]^3."""
    x, w = np.polynomial.legendre.leggauss(order)
    P = np.array(np.meshgrid(x, x, x, indexing="ij")).reshape(3, -1).T
    W = np.prod(np.array(np.meshgrid(w, w, w, indexing="ij")).reshape(3, -1).T, axis=1)
    return P, W


def hex8_shape(xi):
    """Trilinear shape functions N (G, 8) and derivatives dN/dxi (G, 8, 3)."""
    t = 1.0 + xi[:, None, :] * XI_NODES[None, :, :]          # (G, 8, 3)
    N = 0.125 * np.prod(t, axis=2)
    dN = np.empty(t.shape)
    for k in range(3):
        others = [j for j in range(3) if j != k]
        dN[:, :, k] = 0.125 * XI_NODES[None, :, k] * t[:, :, others[0]] * t[:, :, others[1]]
    return N, dN


def hex8_geometry(X, order=2):
    """Physical derivatives dN/dx (E, G, 8, 3), weights |J| w (E, G) and N (G, 8).

    ``X``: (E, 8, 3) node coordinates. Raises SSIError on a non-positive
    Jacobian (inverted or degenerate brick, or a wrong node order).
    """
    P, W = gauss_hex(order)
    N, dN = hex8_shape(P)
    J = np.matmul(X.transpose(0, 2, 1)[:, None], dN[None])   # (E, G, 3, 3): dx_i / dxi_k
    det = np.linalg.det(J)
    if np.any(det <= 0):
        bad = np.unique(np.nonzero(det <= 0)[0])
        raise SSIError(f"{bad.size} hex8 cell(s) have a non-positive Jacobian (first: cell {bad[0]}): "
                       "inverted or degenerate bricks, or a node order other than gmsh's")
    Jinv = np.linalg.inv(J)                                  # dxi_k / dx_i
    dNdx = np.matmul(dN[None], Jinv)                         # (E, G, 8, 3)
    return dNdx, det * W[None, :], N


def lame(E, nu):
    """Lame constants (lambda, mu) from Young's modulus and Poisson's ratio."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def hex8_stiffness(X, E, nu):
    """Element stiffness matrices (E, 24, 24), dof order 3*a + i. Vectorised.

    Both terms are batched products over (Gauss point, direction):
    T1[a i, b j] = sum_g w N_a,i N_b,j and T2[a, b] = sum_g,k w N_a,k N_b,k.
    """
    lam, mu = lame(E, nu)
    G, wd, _ = hex8_geometry(X)
    ne, ng = G.shape[:2]
    Gf = G.reshape(ne, ng, 24)                               # (a, i) -> 3a + i
    T1 = np.matmul((Gf * wd[:, :, None]).transpose(0, 2, 1), Gf).reshape(ne, 8, 3, 8, 3)
    Gk = G.transpose(0, 2, 1, 3).reshape(ne, 8, 3 * ng)      # a x (g, k)
    T2 = np.matmul(Gk * np.repeat(wd, 3, axis=1)[:, None, :], Gk.transpose(0, 2, 1))
    Ke = lam * T1 + mu * T1.transpose(0, 1, 4, 3, 2)
    Ke += mu * T2[:, :, None, :, None] * np.eye(3)[None, None, :, None, :]
    return Ke.reshape(-1, 24, 24)


def hex8_lumped_mass(X, rho):
    """Lumped nodal masses (E, 8): rho int N_a dV (row sums of the consistent mass)."""
    _, wd, N = hex8_geometry(X)
    return rho * np.einsum("ga,eg->ea", N, wd)


def hex8_stiffness_reference(X, E, nu):
    """Slow textbook K_e = sum_g B^T D B |J| w, one element and point at a time."""
    lam, mu = lame(E, nu)
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[np.arange(3), np.arange(3)] += 2 * mu
    D[np.arange(3, 6), np.arange(3, 6)] = mu
    P, W = gauss_hex(2)
    N, dN = hex8_shape(P)
    out = np.zeros((X.shape[0], 24, 24))
    for e in range(X.shape[0]):
        for g in range(P.shape[0]):
            J = X[e].T @ dN[g]
            dx = dN[g] @ np.linalg.inv(J)                    # (8, 3)
            B = np.zeros((6, 24))
            for a in range(8):
                gx, gy, gz = dx[a]
                B[:, 3 * a:3 * a + 3] = [[gx, 0, 0], [0, gy, 0], [0, 0, gz],
                                         [0, gz, gy], [gz, 0, gx], [gy, gx, 0]]
            out[e] += B.T @ D @ B * np.linalg.det(J) * W[g]
    return out


@dataclass
class Material:
    E: float
    nu: float
    rho: float


class Layout:
    """Node-blocked ownership of the 3N dofs on ``comm`` (collective)."""

    def __init__(self, n_nodes, comm):
        PETSc = init()
        self.comm = comm
        self.n_nodes = int(n_nodes)
        self._tmpl = PETSc.Vec().createMPI((PETSc.DECIDE, 3 * self.n_nodes), bsize=3, comm=comm)
        r0, r1 = self._tmpl.getOwnershipRange()
        self.r0, self.r1 = r0, r1
        self.n0, self.n1 = r0 // 3, r1 // 3

    def vec(self):
        v = self._tmpl.duplicate()
        v.zeroEntries()
        return v

    @property
    def n_local(self):
        return self.r1 - self.r0

    def nodal_vec(self, values):
        """Vec from a replicated (N, 3) array."""
        v = self.vec()
        v.getArray()[:] = np.asarray(values, float)[self.n0:self.n1].ravel()
        return v


def local_cells(mesh, layout):
    """Bricks touching at least one node this rank owns."""
    owned = (mesh.cells >= layout.n0) & (mesh.cells < layout.n1)
    return np.nonzero(owned.any(axis=1))[0]


def local_stiffness_csr(mesh, mat, layout, chunk=20000):
    """Owned rows of K as a scipy CSR (local rows, global columns), summed."""
    from scipy.sparse import csr_matrix
    cells = mesh.cells[local_cells(mesh, layout)]
    n = 3 * layout.n_nodes
    A = csr_matrix((layout.n_local, n))
    for s in range(0, cells.shape[0], chunk):
        c = cells[s:s + chunk]
        Ke = hex8_stiffness(mesh.coords[c], mat.E, mat.nu)
        dofs = (3 * c[:, :, None] + np.arange(3)).reshape(-1, 24)
        rows = np.broadcast_to(dofs[:, :, None], Ke.shape).ravel()
        cols = np.broadcast_to(dofs[:, None, :], Ke.shape).ravel()
        keep = (rows >= layout.r0) & (rows < layout.r1)
        A = A + csr_matrix((Ke.ravel()[keep], (rows[keep] - layout.r0, cols[keep])),
                           shape=(layout.n_local, n))
    A.sum_duplicates()
    A.sort_indices()
    return A


def csr_to_petsc(A, layout):
    """Collective: distributed AIJ (bs 3) with exact preallocation from ``A``."""
    PETSc = init()
    cols = A.indices
    diag = (cols >= layout.r0) & (cols < layout.r1)
    row_of = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    d_nnz = np.bincount(row_of[diag], minlength=A.shape[0]).astype(PETSc.IntType)
    o_nnz = (np.diff(A.indptr) - d_nnz).astype(PETSc.IntType)
    M = PETSc.Mat().createAIJ(size=((layout.n_local, A.shape[1]), (layout.n_local, A.shape[1])),
                              bsize=3, nnz=(d_nnz, o_nnz), comm=layout.comm)
    M.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
    M.setValuesCSR(A.indptr.astype(PETSc.IntType), cols.astype(PETSc.IntType), A.data,
                   addv=PETSc.InsertMode.ADD_VALUES)
    M.assemble()
    return M


def local_lumped_mass(mesh, mat, layout):
    """Nodal masses of the nodes this rank owns (numpy, no communication)."""
    cells = mesh.cells[local_cells(mesh, layout)]
    me = hex8_lumped_mass(mesh.coords[cells], mat.rho)
    return np.bincount(cells.ravel(), weights=me.ravel(), minlength=mesh.n_nodes)[layout.n0:layout.n1]


def lumped_mass_vec(mesh, mat, layout, local=None):
    """Collective: Vec of nodal masses (each repeated for the 3 components)."""
    m = local_lumped_mass(mesh, mat, layout) if local is None else local
    v = layout.vec()
    v.getArray()[:] = np.repeat(m, 3)
    return v


def diagonal_mat(d):
    """Collective: diagonal AIJ matrix with the layout and entries of the Vec ``d``."""
    PETSc = init()
    M = PETSc.Mat().createAIJ(size=(d.getSizes(), d.getSizes()), nnz=(1, 0), comm=d.getComm())
    M.setDiagonal(d)
    M.assemble()
    return M


def owned_dofs(dofs, obj):
    """The global ``dofs`` in the ownership range of ``obj`` (Mat or Vec), as PETSc ints."""
    PETSc = init()
    r0, r1 = obj.getOwnershipRange()
    d = np.asarray(dofs, dtype=np.int64)
    return d[(d >= r0) & (d < r1)].astype(PETSc.IntType)


def mean_diagonal(A):
    """Collective: mean of the diagonal of A."""
    d = A.getDiagonal()
    mean = d.sum() / d.getSize()
    d.destroy()
    return mean


def eliminate_dofs(A, owned):
    """Collective: zero the rows and columns ``owned`` (global, owned by this rank) of A
    in place and put the mean diagonal of A on their diagonal; returns A."""
    A.zeroRowsColumns(owned, diag=mean_diagonal(A))
    return A


def assemble(mesh, mat, layout):
    """Collective: (K Mat, lumped mass Vec). Checks the brick Jacobians first; an error on
    any rank (SSIError or not) is raised on every rank as a one-line SSIError."""
    with event("FEM_assembly"):
        err = None
        A = m = None
        try:                                   # local numpy work only: nothing collective in here
            A = local_stiffness_csr(mesh, mat, layout)
            m = local_lumped_mass(mesh, mat, layout)
        except SSIError as exc:
            err = str(exc)
        except Exception as exc:  # noqa: BLE001 -- a failure on one rank must reach the others
            err = f"assembling K and M failed on rank {layout.comm.getRank()}: {one_line(exc)}"
        collective_error(err, layout.comm)
        return csr_to_petsc(A, layout), lumped_mass_vec(mesh, mat, layout, m)


def check_mass(m, free_mask, comm):
    """Collective: SSIError unless the lumped mass is positive on every free dof.

    With K positive semi-definite and M > 0, D = M/(alpha dt^2) + ... + K
    (paper eq. 15) is positive definite; a zero or negative nodal mass makes
    D singular or indefinite.
    """
    a = m.getArray(readonly=True)
    f = free_mask.getArray(readonly=True) > 0
    nz = int(np.sum((a <= 0) & f))
    neg = int(np.sum((a < 0) & f))
    mpi = comm.tompi4py()
    nz, neg = mpi.allreduce(nz), mpi.allreduce(neg)
    if nz:
        collective_error(f"lumped mass is <= 0 at {nz} free dof(s) ({neg} negative): D = M/(alpha dt^2) + delta/(alpha dt) C + K "
                         "would be singular or indefinite (nodes outside every brick, or rho <= 0)", comm)
