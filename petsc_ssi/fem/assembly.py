"""The distributed stiffness K and lumped mass M of a structure of any mix of elements.

Element kernels live in the registry (``fem/elements/``: hex8, frame, shell),
vectorised over the cells of a block; this module only scatters them.

Parallel layout: the dof map (``dofmap.DofMap``): dofs numbered node by node,
rank r owns the nodes [n0, n1) and their dofs [r0, r1) (block size 3; a hex8
model: dof 3*node + component, as before the dof map). Each rank computes the
element matrices of every cell that touches one of its nodes, keeps the rows it
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

from ..petsc import init, SSIError, collective, collective_error
from ..monitor import event
from .mesh import one_line

from .elements.hex8 import (XI_NODES, gauss_hex, hex8_shape, hex8_geometry, lame,  # noqa: F401 (compat)
                             hex8_stiffness, hex8_lumped_mass, hex8_stiffness_reference)
from .elements import Props
from .dofmap import DofMap  # noqa: F401


@dataclass
class Material:
    E: float
    nu: float
    rho: float


def _props(block, material):
    """The block's properties, or the legacy material (a hex8 mesh assembled with a Material)."""
    if block.props is not None:
        return block.props
    if material is None:
        raise SSIError(f"part '{block.part}' has no properties")
    return Props(E=material.E, nu=material.nu, rho=material.rho)


def local_cells(cells, dofmap):
    """Indices of the cells touching at least one node this rank owns."""
    owned = (cells >= dofmap.n0) & (cells < dofmap.n1)
    return np.nonzero(owned.any(axis=1))[0]


def local_stiffness_csr(mesh, mat, dofmap, chunk=20000):
    """Owned rows of K as a scipy CSR (local rows, global columns), summed over the blocks."""
    from scipy.sparse import csr_matrix
    n = dofmap.size
    A = csr_matrix((dofmap.n_local, n))
    for blk in mesh.blocks:
        el, props = blk.element, _props(blk, mat)
        cells = blk.cells[local_cells(blk.cells, dofmap)]
        for s in range(0, cells.shape[0], chunk):
            c = cells[s:s + chunk]
            Ke = el.stiffness(mesh.coords[c], props)
            dofs = dofmap.cell_dofs(c, el.dof_names, props.released)
            rows = np.broadcast_to(dofs[:, :, None], Ke.shape).ravel()
            cols = np.broadcast_to(dofs[:, None, :], Ke.shape).ravel()
            keep = (rows >= dofmap.r0) & (rows < dofmap.r1)
            A = A + csr_matrix((Ke.ravel()[keep], (rows[keep] - dofmap.r0, cols[keep])),
                               shape=(dofmap.n_local, n))
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


def block_masses(mesh, mat=None):
    """Replicated: [(block, lumped masses (E, nd))] of every block (numpy, no communication)."""
    return [(blk, blk.element.lumped_mass(mesh.coords[blk.cells], _props(blk, mat))) for blk in mesh.blocks]


def local_lumped_mass(mesh, mat, dofmap):
    """Lumped masses of the dofs this rank owns (numpy, no communication)."""
    m = np.zeros(dofmap.n_local)
    for blk in mesh.blocks:
        el = blk.element
        cells = blk.cells[local_cells(blk.cells, dofmap)]
        props = _props(blk, mat)
        me = el.lumped_mass(mesh.coords[cells], props)
        d = dofmap.cell_dofs(cells, el.dof_names, props.released).ravel()
        own = (d >= dofmap.r0) & (d < dofmap.r1)
        m += np.bincount(d[own] - dofmap.r0, weights=me.ravel()[own], minlength=dofmap.n_local)
    return m


def lumped_mass_vec(mesh, mat, layout, local=None):
    """Collective: Vec of the lumped mass per dof."""
    m = local_lumped_mass(mesh, mat, layout) if local is None else local
    v = layout.vec()
    v.getArray()[:] = m
    return v


def mass_report(mesh, mat=None):
    """Replicated: per part, the total mass [kg] (x translations) and the rotary inertia
    [kg m^2] summed over its rotation dofs (rx, ry, rz), and the structure's total mass."""
    parts = {}
    for blk, me in block_masses(mesh, mat):
        k = len(blk.element.dof_names)
        me = me.reshape(me.shape[0], -1, k)
        r = parts.setdefault(blk.part, {"element": blk.element.name, "cells": 0, "mass": 0.0,
                                        "rotary": np.zeros(3)})
        r["cells"] += me.shape[0]
        r["mass"] += float(me[:, :, 0].sum())
        if k == 6:
            r["rotary"] += me[:, :, 3:].sum(axis=(0, 1))
    return parts, sum(r["mass"] for r in parts.values())


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
    """Collective: (K Mat, lumped mass Vec) of every block of ``mesh`` in the dof map
    ``layout``; ``mat`` (a Material) gives the properties of blocks without their own
    (a hex8 mesh built without parts), else None. An error on any rank (SSIError or
    not) is raised on every rank as a one-line SSIError."""
    with event("FEM_assembly"):
        A = m = None
        with collective(layout.comm, "assembling K and M"):      # local numpy work only in the block
            A = local_stiffness_csr(mesh, mat, layout)
            m = local_lumped_mass(mesh, mat, layout)
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
