"""Natural modes: SLEPc against dense eigh; the hex8 cantilever against Euler-Bernoulli."""
import numpy as np
import pytest
from scipy.linalg import eigh

from fem_helpers import small_system, dense, run_cli
from petsc_ssi.fem.loads import fixed_dofs
from petsc_ssi.fem.mesh import structured_box
from petsc_ssi.fem.modes import compute_modes

pytestmark = pytest.mark.unit


def dense_modes(K, m, fixed, k):
    Kd, md = dense(K), m.getArray().copy()
    free = np.setdiff1d(np.arange(Kd.shape[0]), fixed)
    lam, X = eigh(Kd[np.ix_(free, free)], np.diag(md[free]), subset_by_index=(0, k - 1))
    return np.sqrt(np.maximum(lam, 0)) / (2 * np.pi), X, free


@pytest.mark.parametrize("fixed_group", ["base", ""])
def test_slepc_matches_dense_eigh(PETSc, fixed_group):
    """Lowest 10 eigenvalues omega^2 (fixed base; free: 6 rigid + 4 flexible) agree to 1e-8 relative
    (of the largest; omega^2, since sqrt amplifies the round-off of the rigid modes' 0) and mode
    shapes to |MAC| > 1 - 1e-8 (flexible, non-degenerate modes)."""
    mesh = structured_box((3, 2, 2), (1.0, 0.6, 0.4), (0, 0, 0))
    K, m, _ = small_system(mesh, E=2e7, nu=0.3, rho=2000.0)
    fixed = fixed_dofs(mesh, fixed_group)
    f_ref, X, free = dense_modes(K, m, fixed, 10)
    f, shapes = compute_modes(K, m, fixed, 10, target=-1.0, prefix="tmodes_")
    assert np.abs(f ** 2 - f_ref ** 2).max() <= 1e-8 * f_ref.max() ** 2
    md = m.getArray()[free]
    first_flexible = 0 if fixed_group else 6
    for i in range(first_flexible, 10):
        x = shapes[i].getArray()[free]
        mac = (x * md) @ X[:, i] / np.sqrt((x * md) @ x * ((X[:, i] * md) @ X[:, i]))
        assert abs(mac) > 1 - 1e-8, (i, mac)
    if not fixed_group:
        assert np.all(f[:6] < 1e-6 * f[6])            # rigid-body modes at 0 Hz


def test_cantilever_first_bending_frequency(PETSc):
    """Hex8 cantilever 1 x 0.1 x 0.1 m (nu = 0), fixed at x = 0, against Euler-Bernoulli
    f1 = 1.8751^2 / (2 pi L^2) sqrt(EI / rho A). Full integration locks in bending, so the error falls
    like h^2 with refinement: 10x1x1 < 25 %, 20x2x2 < 6 %, 40x4x4 < 1.5 % and at least 3x smaller per
    level. (Below ~1 % the 3D solution parts from Euler-Bernoulli: shear and rotary inertia, L/h = 10.)"""
    E, rho, L, h = 1e7, 1000.0, 1.0, 0.1
    f_eb = 1.875104 ** 2 / (2 * np.pi) * np.sqrt(E * h ** 4 / 12 / (rho * h * h * L ** 4))
    errors = []
    for n, tol in (((10, 1, 1), 0.25), ((20, 2, 2), 0.06), ((40, 4, 4), 0.015)):
        mesh = structured_box(n, (L, h, h), (0, 0, 0))
        K, m, _ = small_system(mesh, E=E, nu=0.0, rho=rho)
        f, _ = compute_modes(K, m, fixed_dofs(mesh, "xmin"), 2, target=-1.0, prefix="tcant_")
        assert f[1] == pytest.approx(f[0], rel=1e-8)   # square section: two equal bending modes
        errors.append(f[0] / f_eb - 1)
        assert 0 < errors[-1] < tol, (n, errors[-1])
    assert errors[1] < errors[0] / 3 and errors[2] < errors[1] / 3


def test_modes_command(tmp_path):
    """petsc-ssi modes: header 'mode,frequency_hz', K rows, alpha_m note, HDF5 mode shapes."""
    import h5py
    out = tmp_path / "modes.h5"
    r = run_cli(["modes", "-ssi_fem_box_cells", "4,4,2", "-ssi_fem_fixed", "base", "-ssi_modes_n", "4",
                 "-ssi_fem_damping_ratio", "0.02", "-ssi_fem_damping_freq", "100", "-ssi_output", str(out)])
    assert r.returncode == 0, r.stdout + r.stderr
    lines = r.stdout.splitlines()
    i = lines.index("mode,frequency_hz")
    rows = [ln.split(",") for ln in lines[i + 1:i + 5]]
    f = np.array([float(c[1]) for c in rows])
    assert [int(c[0]) for c in rows] == [1, 2, 3, 4] and np.all(np.diff(f) >= 0) and f[0] > 10
    assert any("alpha_m = 2 zeta omega" in ln for ln in lines)
    # the participation table: an effective height only where the mode moves at least 0.01 % of the mass that way
    j = next(k for k, ln in enumerate(lines) if ln.startswith("mode,frequency_hz,meff_x_kg"))
    assert lines[j] == ("mode,frequency_hz,meff_x_kg,meff_y_kg,meff_z_kg,ratio_x,ratio_y,ratio_z,cum_x,cum_y,cum_z,"
                        "height_x_m,height_y_m"), lines[j]            # a clean CSV header: the notes on the line before
    part = [ln.split(",") for ln in lines[j + 1:j + 5]]
    shown = 0
    for c in part:
        for d in (0, 1):
            ratio, height = float(c[5 + d]), c[11 + d]
            assert (height == "-") == (ratio < 1e-4), c
            shown += height != "-"
            assert height == "-" or 0.0 < float(height) <= 0.5 + 1e-9, c     # (within the 0.5 m box)
    assert shown >= 2, part
    with h5py.File(out) as h:
        assert np.allclose(h.attrs["frequencies_hz"], f, rtol=1e-7)
        s = h["mode_shape_000000"][:]
        assert s.shape == (75, 3) and np.abs(s).max() == pytest.approx(1.0)


def test_inertia_count_matches_dense(PETSc):
    """count_below (negative pivots of the MUMPS LDL^T of K - sigma M) equals the number of dense
    eigenvalues below sigma, for sigma in three gaps of the spectrum and below the lowest one."""
    from petsc_ssi.fem.modes import _submatrices, count_below
    mesh = structured_box((3, 2, 2), (1.0, 0.6, 0.4), (0, 0, 0))
    K, m, _ = small_system(mesh, E=2e7, nu=0.3, rho=2000.0)
    fixed = fixed_dofs(mesh, "base")
    Kf, Mf, _, free = _submatrices(K, m, fixed)
    lam = eigh(dense(K)[np.ix_(free, free)], np.diag(m.getArray()[free]), eigvals_only=True)
    for k in (0, 5, 17, 40):
        sigma = 0.5 * (lam[k - 1] + lam[k]) if k else 0.5 * lam[0]
        assert count_below(Kf, Mf, sigma) == k


def test_missed_modes_are_found_by_the_inertia_check(PETSc):
    """A shift-and-invert target far up the spectrum (near the 40th eigenvalue) makes the first solve
    return eigenvalues around the target instead of the lowest ones. The inertia check sees that more
    eigenvalues lie below its shift than were found, solves again with more, and the 10 lowest agree
    with dense eigh to 1e-8; with a single attempt allowed, the same case is a clear error."""
    from petsc_ssi.petsc import SSIError
    mesh = structured_box((3, 2, 2), (1.0, 0.6, 0.4), (0, 0, 0))
    K, m, _ = small_system(mesh, E=2e7, nu=0.3, rho=2000.0)
    fixed = fixed_dofs(mesh, "base")
    f_ref, _, _ = dense_modes(K, m, fixed, 41)
    target = (2 * np.pi * f_ref[40]) ** 2
    f, _ = compute_modes(K, m, fixed, 10, target=target, prefix="tmiss_")
    assert np.abs(f ** 2 - f_ref[:10] ** 2).max() <= 1e-8 * f_ref[:10].max() ** 2
    with pytest.raises(SSIError, match="inertia of K - sigma M counts"):
        compute_modes(K, m, fixed, 10, target=target, prefix="tmiss1_", max_attempts=1)
