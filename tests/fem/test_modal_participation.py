"""Modal participating mass and effective height (issue 43, item 2): `petsc-ssi modes` on a 3-storey
shear building (one Timoshenko column, one element per storey, floors that cannot rotate or move
vertically, lumped floor masses of 30, 25 and 20 t, a column of negligible mass) against the closed form
of the lumped shear building: K = k tridiag(-1, 2, -1) (top 1), M = diag(m). Every quantity of the
shapes (effective masses, their shares, effective heights h* = sum m_j h_j phi_j / sum m_j phi_j) does
not depend on k (equal storeys); the frequencies sqrt(k lambda) with the fixed-guided Timoshenko storey
stiffness k = 1/(h^3/(12 E I) + h/(kappa G A)). All six modes are computed, so the effective masses sum to
the total mass in x and y. On 1 and 2 ranks."""
import h5py
import numpy as np
import pytest

from fem_helpers import run_cli

pytestmark = pytest.mark.mpi

H, E, NU = 3.0, 30e9, 0.2
MASS = np.array([30e3, 25e3, 20e3])
B, D = 0.3, 0.5                          # a rectangle: x and y modes apart


def _msh(path):
    from petsc_ssi.mesh.gmsh import write_msh
    X = np.array([[0.0, 0.0, H * k] for k in range(4)])
    groups = {"column": ("line2", np.array([[0, 1], [1, 2], [2, 3]])), "base": ("point", np.array([[0]])),
              "floors": ("point", np.array([[1], [2], [3]]))}
    write_msh(path, X, groups)


def closed_form():
    K = np.diag([2.0, 2.0, 1.0]) - np.diag([1.0, 1.0], 1) - np.diag([1.0, 1.0], -1)     # per unit k
    lam, phi = np.linalg.eigh(np.diag(1 / np.sqrt(MASS)) @ K @ np.diag(1 / np.sqrt(MASS)))
    phi = np.diag(1 / np.sqrt(MASS)) @ phi                                              # M-orthonormal
    L = phi.T @ MASS
    meff = L ** 2                                                                        # phi^T M phi = 1
    h = H * np.arange(1, 4)
    hstar = (phi.T @ (MASS * h)) / L
    return lam, meff, hstar


@pytest.mark.parametrize("n", [1, 2])
def test_modes_participation_against_the_shear_building(tmp_path, n):
    msh = str(tmp_path / "col.msh")
    _msh(msh)
    out = tmp_path / "m.h5"
    r = run_cli(["modes", "-ssi_fem_mesh", msh, "-ssi_fem_parts", "column", "-ssi_fem_part_column_element", "frame",
                 "-ssi_fem_part_column_E", str(E), "-ssi_fem_part_column_nu", str(NU),
                 "-ssi_fem_part_column_rho", "1e-9", "-ssi_fem_part_column_section", f"{B},{D}",
                 "-ssi_fem_part_column_orientation", "1,0,0", "-ssi_fem_fixed", "base,floors:uz+rx+ry+rz",
                 "-ssi_fem_point_mass", ";".join(f"0,0,{H * (k + 1)},{m}" for k, m in enumerate(MASS)),
                 "-ssi_modes_n", "6", "-ssi_output", str(out)], n=n)
    assert r.returncode == 0, r.stdout + r.stderr
    lam, meff, hstar = closed_form()
    from petsc_ssi.fem.parts import rect_section
    s = rect_section(B, D)
    G = E / (2 * (1 + NU))
    ks = [1.0 / (H ** 3 / (12 * E * s[I]) + H / (5.0 / 6.0 * G * s["area"])) for I in ("Iy", "Iz")]
    f_ref = np.sort(np.concatenate([np.sqrt(k * lam) / (2 * np.pi) for k in ks]))
    with h5py.File(out, "r") as f:
        g = f["modal_participation"]
        freq = g["frequency"][()]
        me, ratio, cum = g["effective_mass"][()], g["effective_mass_ratio"][()], g["cumulative_mass_ratio"][()]
        hh, tot = g["effective_height"][()], g["total_mass"][()]
        need = g["modes_for_90_percent"][()]
        assert g["effective_mass"].attrs["unit"].startswith("kg") and g["effective_height"].attrs["unit"] == "m"
        assert g["frequency"].attrs["unit"] == "Hz"
    assert freq == pytest.approx(f_ref, rel=1e-8)
    assert tot[:2] == pytest.approx([MASS.sum()] * 2, rel=1e-9)          # the column's 1e-9 kg/m^3 is nothing
    for d in range(2):                                                   # x, y: each mode belongs to one
        on = np.flatnonzero(ratio[:, d] > 1e-9)
        assert len(on) == 3
        assert me[on, d] == pytest.approx(meff, rel=1e-8)               # the closed form's order (ascending f)
        assert hh[on, d] == pytest.approx(hstar, rel=1e-8)
        assert me[:, d].sum() == pytest.approx(MASS.sum(), rel=1e-9)     # all modes: the total mass
        assert cum[-1, d] == pytest.approx(1.0, rel=1e-9)
    print("effective masses", meff, "heights", hstar, "frequencies", freq)
    # the number of modes for 90 % (the closed form's first mode has 91.7 % here): in the output's order,
    # where x and y modes mix, the index of that mode of the direction
    n_ref = int(np.argmax(np.cumsum(meff) / MASS.sum() >= 0.9)) + 1
    for d in range(2):
        on = np.flatnonzero(ratio[:, d] > 1e-9)
        assert need[d] == on[n_ref - 1] + 1
    assert "modes for 90 % of the mass: x " in r.stdout
