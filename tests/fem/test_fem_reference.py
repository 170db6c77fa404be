"""Full runs of ``-ssi_problem fem`` against references built without the driver.

A 2 x 2 x 2 brick block (1 x 1 x 0.5 m, E = 300e6, nu = 0.2, rho = 2000), base
fixed, top pressure p0 = 1000 N/m^2 as a box pulse of t0 = 7.55 ms (inside a
step of both dt), alpha_m = 30 1/s, receivers at the top centre and a top
corner. The driver renumbers the nodes (RCM) and snaps the receivers.

  * the same GreenIntegrator run in-process on the RCM-renumbered mesh (the
    same matrices as the driver's), step by step with the exact cell-mean
    load samples: the receiver series must agree to 1e-12 (checks the
    plumbing: options, mesh, loads, fixed dofs, receivers, the initial half
    impulse, the sampling);
  * the exact solution of the semi-discrete system M a + alpha_m M v + K u =
    F h(t) by modal superposition (dense eigh, closed-form damped box
    response of each mode): the error of the run must fall at order 2 from
    dt = 1e-4 s to 5e-5 s (omega_max dt <= 0.3) and be < 2.5 % at 5e-5 s.
"""
from types import SimpleNamespace

import h5py
import numpy as np
import pytest
from scipy.linalg import eigh

from fem_helpers import run_cli, small_system, dense, vec_from
from petsc_ssi.fem.integrators import GreenIntegrator
from petsc_ssi.fem.loads import History, fixed_dofs, nodal_load
from petsc_ssi.fem.mesh import structured_box, renumber_rcm

pytestmark = pytest.mark.unit

E, NU, RHO, AM, P0, T0, T = 300e6, 0.2, 2000.0, 30.0, 1000.0, 7.55e-3, 0.03
RECEIVERS = np.array([[0.0, 0.0, 0.5], [0.5, 0.5, 0.5]])
DTS = (1e-4, 5e-5)


@pytest.fixture(scope="module")
def cli_runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("reference")
    out = {}
    for dt in DTS:
        path = str(d / f"dt{dt:g}.h5")
        r = run_cli(["-ssi_problem", "fem", "-ssi_fem_mesh", "box", "-ssi_fem_box_cells", "2,2,2",
                     "-ssi_fem_E", str(E), "-ssi_fem_nu", str(NU), "-ssi_fem_rho", str(RHO),
                     "-ssi_fem_alpha_m", str(AM), "-ssi_fem_fixed", "base", "-ssi_fem_load_group", "top",
                     "-ssi_fem_load_p0", str(P0), "-ssi_fem_load_history", "box", "-ssi_fem_load_t0", str(T0),
                     "-ssi_dt", str(dt), "-ssi_t_end", str(T), "-ssi_output_stride", "0",
                     "-ssi_receivers", ";".join(",".join(f"{c:g}" for c in p) for p in RECEIVERS),
                     "-ssi_output", path])
        assert r.returncode == 0, r.stdout + r.stderr
        with h5py.File(path) as f:
            out[dt] = (f["receivers/t"][:], f["receivers/u"][:])
    return out


def make_block(renumber):
    """(mesh, K, m, fixed, F (3N,), receiver dofs (R*3,))."""
    mesh = structured_box((2, 2, 2))
    mesh = renumber_rcm(mesh) if renumber else mesh
    K, m, _ = small_system(mesh, E, NU, RHO)
    fixed = fixed_dofs(mesh, "base")
    F, _ = nodal_load(mesh, SimpleNamespace(fem_load_p0=P0, fem_load_group="top", fem_point_load=""))
    nodes = [int(np.argmin(np.linalg.norm(mesh.coords - p, axis=1))) for p in RECEIVERS]
    assert np.allclose(mesh.coords[nodes], RECEIVERS)
    dofs = (3 * np.asarray(nodes)[:, None] + np.arange(3)).ravel()
    return mesh, K, m, fixed, F.ravel(), dofs


@pytest.fixture(scope="module")
def block(PETSc):
    return make_block(renumber=False)


@pytest.fixture(scope="module")
def block_rcm(PETSc):
    return make_block(renumber=True)


def modal_exact(block, t):
    """u(t) at the receiver dofs, (len(t), R, 3): exact semi-discrete box response."""
    mesh, K, m, fixed, F, dofs = block
    free = np.setdiff1d(np.arange(3 * mesh.n_nodes), fixed)
    lam, phi = eigh(dense(K)[np.ix_(free, free)], np.diag(m.getArray()[free]))   # M-orthonormal
    w, a = np.sqrt(lam), 0.5 * AM
    wd = np.sqrt(w ** 2 - a ** 2)                                                # all underdamped

    def step(s):            # response of q'' + AM q' + w^2 q = H(s)
        s = np.asarray(s, float)[:, None]
        r = (1 - np.exp(-a * s) * (np.cos(wd * s) + a / wd * np.sin(wd * s))) / w ** 2
        return np.where(s > 0, r, 0.0)

    q = (step(t) - step(t - T0)) * (phi.T @ F[free])[None, :]     # box = H(t) - H(t - t0)
    u = np.zeros((len(t), 3 * mesh.n_nodes))
    u[:, free] = q @ phi.T
    return u[:, dofs].reshape(len(t), -1, 3)


def test_run_equals_in_process_integrator(cli_runs, block_rcm):
    """The driver's receiver series == GreenIntegrator stepped here with History cell means, 1e-12."""
    mesh, K, m, fixed, F, dofs = block_rcm
    dt = DTS[0]
    t, u = cli_runs[dt]
    n_steps = int(round(T / dt))
    hist = History("box", T0)
    integ = GreenIntegrator(K, m, dt, AM, fixed, prefix="tref_")
    integ.start(f0=vec_from(hist.cell_mean(0, dt) * F, m))
    ref = [integ.u.getArray()[dofs].copy()]
    for n in range(1, n_steps + 1):
        integ.step(vec_from(hist.cell_mean(n, dt) * F, m))
        ref.append(integ.u.getArray()[dofs].copy())
    integ.destroy()
    ref = np.array(ref).reshape(n_steps + 1, -1, 3)
    assert t == pytest.approx(np.arange(n_steps + 1) * dt, abs=1e-15)
    assert u.shape == ref.shape
    assert np.abs(u - ref).max() <= 1e-12 * np.abs(ref).max()


def test_run_converges_to_modal_superposition(cli_runs, block):
    """Max-in-time error of the receiver series against the exact semi-discrete solution: observed
    order 2 +- 0.15 between dt = 1e-4 and 5e-5 s, and below 2.5 % (relative to max |u|) at 5e-5 s."""
    errs = []
    for dt in DTS:
        t, u = cli_runs[dt]
        ue = modal_exact(block, t)
        errs.append(np.abs(u - ue).max() / np.abs(ue).max())
    order = np.log2(errs[0] / errs[1])
    assert abs(order - 2) < 0.15, (order, errs)
    assert errs[1] < 2.5e-2, errs
