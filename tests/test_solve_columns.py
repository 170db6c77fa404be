"""petsc.solve_columns (the coupled run's interface matrices): many right-hand sides solved chunk by
chunk with one multi-right-hand-side solve of MUMPS's factors, equal to one ksp.solve per column;
an iterative KSP solves column by column, and its divergence is an SSIError."""
import numpy as np
import pytest

from petsc_ssi.petsc import init, solve_columns, SSIError

pytestmark = pytest.mark.unit

PETSc = init()


def _system(n=60):
    A = PETSc.Mat().createAIJ([n, n], nnz=3, comm=PETSc.COMM_WORLD)
    r0, r1 = A.getOwnershipRange()
    for i in range(r0, r1):
        A[i, i] = 4.0 + 0.01 * i
        if i > 0:
            A[i, i - 1] = -1.0
        if i < n - 1:
            A[i, i + 1] = -1.3
    A.assemble()
    return A


def _solve_all(ksp, A, m, chunk, by_block=None):
    """(solve_columns' solutions, one ksp.solve per column); ``by_block``: the right-hand sides also
    given chunk by chunk (``block``), "array" for every chunk, "none" where it answers None (then
    ``fill``, which must then be called for exactly those columns)."""
    rng = np.random.default_rng(3)
    rhs = rng.standard_normal((m, A.getSize()[0]))
    got = np.zeros_like(rhs)
    filled = []
    r0, r1 = A.getOwnershipRange()

    def fill(j, b):
        filled.append(j)
        b.getArray()[:] = rhs[j, r0:r1]

    def block(j0, j1):
        return None if by_block == "none" and j0 > 0 else rhs[j0:j1, r0:r1].T

    def take(j, x):
        got[j, r0:r1] = x.getArray(readonly=True)
    solve_columns(ksp, A.createVecRight(), m, fill, take, chunk=chunk, block=block if by_block else None)
    assert filled == ([] if by_block == "array" else list(range(chunk, m)) if by_block == "none" else list(range(m)))
    ref = np.zeros_like(rhs)
    b, x = A.createVecs()
    for j in range(m):
        b.getArray()[:] = rhs[j, r0:r1]
        ksp.solve(b, x)
        ref[j, r0:r1] = x.getArray(readonly=True)
    return got, ref


@pytest.mark.parametrize("by_block", [None, "array", "none"])
@pytest.mark.parametrize("kind", ["mumps", "cg"])
def test_columns_equal_single_solves(kind, by_block):
    A = _system()
    ksp = PETSc.KSP().create(PETSc.COMM_WORLD)
    ksp.setOperators(A)
    if kind == "mumps":
        ksp.setType("preonly")
        ksp.getPC().setType("lu")
        ksp.getPC().setFactorSolverType("mumps")
    else:
        ksp.setType("gmres")
        ksp.getPC().setType("jacobi")
        ksp.setTolerances(rtol=1e-13)
    ksp.setUp()
    PETSc.Log.begin()
    ev = PETSc.Log.Event("MatMatSolve")
    before = ev.getPerfInfo()["count"]
    got, ref = _solve_all(ksp, A, 7, chunk=3, by_block=by_block)    # chunks of 3, 3 and 1 columns
    assert ev.getPerfInfo()["count"] - before == (3 if kind == "mumps" else 0)   # the batched path, or not
    assert np.abs(got - ref).max() <= 1e-13 * np.abs(ref).max()
    assert np.abs(got).min() >= 0 and np.abs(got).max() > 0


def test_an_iterative_divergence_is_named():
    A = _system()
    ksp = PETSc.KSP().create(PETSc.COMM_WORLD)
    ksp.setOperators(A)
    ksp.setType("gmres")
    ksp.getPC().setType("none")
    ksp.setTolerances(rtol=1e-15, max_it=2)
    ksp.setConvergenceTest(None)
    ksp.setErrorIfNotConverged(False)
    ksp.setUp()
    with pytest.raises(SSIError, match="a solve for column 0 of 4 diverged"):
        solve_columns(ksp, A.createVecRight(), 4, lambda j, b: b.set(1.0), lambda j, x: None)
