"""Static limit: a slowly applied, then constant, load with damping settles to K u = f."""
from types import SimpleNamespace

import numpy as np
import pytest

from fem_helpers import small_system, vec_from
from petsc_ssi.fem.integrators import GreenIntegrator, NewmarkIntegrator
from petsc_ssi.fem.loads import History, fixed_dofs, nodal_load
from petsc_ssi.fem.mesh import structured_box
from petsc_ssi.fem.static import static_solve

pytestmark = pytest.mark.unit


def settle(cls, solver, prefix):
    """The paper's block (4x4x2 bricks), base fixed, top pressure ramped over 0.05 s, then held;
    alpha_m = 650 1/s (zeta ~ 0.5 at the first mode, 104 Hz): every mode decays like exp(-325 t)."""
    mesh = structured_box((4, 4, 2), (1.0, 1.0, 0.5), (-0.5, -0.5, 0.0))
    K, m, layout = small_system(mesh, E=300e6, nu=0.2, rho=2000.0)
    fixed = fixed_dofs(mesh, "base")
    cfg = SimpleNamespace(fem_load_p0=1000.0, fem_load_group="top", fem_point_load="0.5,0.5,0.5,200,0,0")
    F, _ = nodal_load(mesh, cfg)
    Fv = layout.nodal_vec(F)
    hist = History("table", table=np.array([[0.0, 0.0], [0.05, 1.0], [1.0, 1.0]]))
    dt, nsteps = 5e-4, 300
    coords = layout.nodal_vec(mesh.coords) if solver == "iterative" else None
    integ = cls(K, m, dt, 650.0, fixed, prefix=prefix, solver=solver, coords_vec=coords)
    integ.start(f0=vec_from(hist.cell_mean(0, dt) * F.ravel(), m))
    for n in range(1, nsteps + 1):
        integ.step(vec_from(hist.cell_mean(n, dt) * F.ravel(), m))
    us = static_solve(K, Fv, fixed, mesh.coords, prefix="tstatic_")
    return integ, us


@pytest.mark.parametrize("cls", [GreenIntegrator, NewmarkIntegrator])
def test_settles_to_static(PETSc, cls):
    """|u(0.15 s) - u_static| <= 1e-9 |u_static| and |v| <= 1e-7 |u_static| / (0.15 s) (the trapezoidal
    fixed point under a constant load is K u = f exactly; what is left is exp(-325 x 0.1) decay)."""
    integ, us = settle(cls, "direct", "tsettle_")
    d = integ.u.copy()
    d.axpy(-1.0, us)
    assert d.norm() <= 1e-9 * us.norm()
    assert integ.velocity().norm() <= 1e-7 * us.norm() / 0.15
    assert us.getArray()[2::3].min() < 0          # the top pressure pushes down


def test_iterative_solver_gives_the_same(PETSc):
    """-ssi_fem_solver iterative (CG + BoomerAMG, rtol 1e-12) == MUMPS to 1e-9."""
    a, _ = settle(GreenIntegrator, "direct", "tsettle_")
    b, _ = settle(GreenIntegrator, "iterative", "tsettle_it_")
    assert b.ksp.getType() == "cg" and b.ksp.getPC().getType() == "hypre"
    d = a.u.copy()
    d.axpy(-1.0, b.u)
    assert d.norm() <= 1e-9 * a.u.norm()
