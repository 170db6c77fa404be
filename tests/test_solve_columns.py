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


def _solve_all(ksp, A, m, chunk):
    rng = np.random.default_rng(3)
    rhs = rng.standard_normal((m, A.getSize()[0]))
    got = np.zeros_like(rhs)

    def fill(j, b):
        b.getArray()[:] = rhs[j]

    def take(j, x):
        got[j] = x.getArray(readonly=True)
    solve_columns(ksp, A.createVecRight(), m, fill, take, chunk=chunk)
    ref = np.zeros_like(rhs)
    b, x = A.createVecs()
    for j in range(m):
        b.getArray()[:] = rhs[j]
        ksp.solve(b, x)
        ref[j] = x.getArray(readonly=True)
    return got, ref


@pytest.mark.parametrize("kind", ["mumps", "cg"])
def test_columns_equal_single_solves(kind):
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
    got, ref = _solve_all(ksp, A, 7, chunk=3)             # chunks of 3, 3 and 1 columns
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
