"""A small, independent scipy assembler for element-level tests (no PETSc, no dof map).

Every node carries ``ndof`` dofs (6 for frames and shells: ux uy uz rx ry rz; 3 for hex8),
dof k of node a is ndof * a + k. Used by the element tests and the obstacle-course
studies to check the kernels alone; the application's own assembly (dof map, PETSc
matrices) is tested against it elsewhere.
"""
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def assemble(n_nodes, blocks, ndof=6):
    """blocks: [(element, cells (E, n), X (E, n, 3) or coords (N, 3), props)].

    Returns (K csr (ndof N, ndof N), m (ndof N,)). An element with fewer dofs per
    node than ``ndof`` fills the first len(dof_names) of each node."""
    n = ndof * n_nodes
    rows, cols, vals = [], [], []
    m = np.zeros(n)
    for elem, cells, coords, props in blocks:
        X = coords[cells] if coords.ndim == 2 else coords
        Ke = elem.stiffness(X, props)
        me = elem.lumped_mass(X, props)
        k = len(elem.dof_names)
        dofs = (ndof * cells[:, :, None] + np.arange(k)).reshape(cells.shape[0], -1)
        rows.append(np.repeat(dofs, dofs.shape[1], axis=1).ravel())
        cols.append(np.tile(dofs, (1, dofs.shape[1])).ravel())
        vals.append(Ke.ravel())
        np.add.at(m, dofs.ravel(), me.ravel())
    K = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    K.sum_duplicates()
    return K, m


def free_dofs(n, fixed):
    mask = np.ones(n, bool)
    mask[np.asarray(fixed, np.int64)] = False
    return np.nonzero(mask)[0]


def solve_static(K, f, fixed):
    """u with K u = f, u = 0 on ``fixed``."""
    free = free_dofs(K.shape[0], fixed)
    u = np.zeros(K.shape[0])
    u[free] = spla.spsolve(K[free][:, free].tocsc(), f[free])
    return u


def lowest_frequencies(K, m, fixed, k=6):
    """The k lowest natural frequencies [Hz] of K x = w^2 diag(m) x on the free dofs (dense
    eigh for small systems, shift-invert Lanczos otherwise)."""
    free = free_dofs(K.shape[0], fixed)
    Kf = K[free][:, free]
    mf = m[free]
    s = 1.0 / np.sqrt(mf)
    A = sp.diags(s) @ Kf @ sp.diags(s)
    if A.shape[0] <= 3000:
        lam = np.linalg.eigvalsh(A.toarray())[:k]
    else:
        lam = np.sort(spla.eigsh(A.tocsc(), k=k, sigma=-1e-6 * abs(A.diagonal()).min(), which="LM",
                                 return_eigenvectors=False))
    return np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi)
