"""Prescribed rigid-body motion of a soil region and its traction resultants (issue 12, item 1;
petsc_ssi/bem/resultants.py): u = h(t) [u0 + theta0 x (x - x_ref)] on -ssi_disp_group, and the
force and moment about x_ref of the region's traction every step (output group 'resultants')."""
import h5py
import numpy as np

from helpers import cli
import pytest

pytestmark = pytest.mark.mpi

# a 2 m x 2 m footing (B = 1 m) on an 8 m x 8 m surface of 0.5 m elements, the paper's soil
BASE = ["-ssi_problem", "bem", "-ssi_mesh_size", "8,8", "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "1,1",
        "-ssi_disp_group", "load", "-ssi_dt", "8e-4", "-ssi_output_stride", "0", "-ssi_warn_beta", "0"]
G = 2000.0 * 316.0 ** 2
NU = ((548 / 316) ** 2 - 2) / (2 * ((548 / 316) ** 2 - 1))


def resultants(path):
    with h5py.File(path) as f:
        g = f["resultants"]
        return {k: g[k][()] for k in g}


# slow tier: the folded quarter model of a rigid motion (30 s; the symmetry-reduced impedance runs == full
#  runs and the half model on a graded gmsh mesh stay)
@pytest.mark.slow
def test_folded_quarter_model_equals_the_full_model(tmp_path):
    """Vertical translation: the quarter model (two symmetry planes, images folded into F and M)
    gives the full model's force to 1e-6 and zero horizontal force and moment; a reference point
    moved by d changes the moment by exactly -d x F (same tractions: the motion has no rotation)."""
    args = BASE + ["-ssi_t_end", "0.02", "-ssi_disp_value", "0,0,-1e-6"]
    q, f, d = (str(tmp_path / f"{k}.h5") for k in "qfd")
    cli(args + ["-ssi_symmetry", "x=sym,y=sym", "-ssi_output", q])
    cli(args + ["-ssi_output", f], nranks=2)
    cli(args + ["-ssi_output", d, "-ssi_disp_ref", "0.5,-0.25,0"], nranks=2)
    Q, F, D = resultants(q), resultants(f), resultants(d)
    fz = F["force"][:, 2]
    assert fz[-1] < 0 and np.abs(Q["force"][:, 2] - fz).max() <= 1e-6 * np.abs(fz).max()
    assert np.abs(Q["force"][:, :2]).max() <= 1e-12 * np.abs(fz).max()
    assert np.abs(Q["moment"]).max() <= 1e-12 * np.abs(fz).max()
    dm = D["moment"] - F["moment"]
    expect = -np.cross(np.array([0.5, -0.25, 0.0]), F["force"])
    assert np.abs(dm - expect).max() <= 1e-9 * np.abs(expect).max()
    assert np.array_equal(F["h"], np.ones(len(F["t"])))          # heaviside: h = 1 from the first step


# slow tier: the make-test budget (10-20 s); the default tier's sibling: test_impedance.py's square footing and test_coupled.py's rigid footing static stiffness
@pytest.mark.slow
def test_static_stiffness_of_the_square_footing(tmp_path):
    """Late-time force of a held vertical translation and moment of a held rocking rotation, against
    Pais and Kausel (1988): K_z = 4.7 G B/(1 - nu), K_ry = 4.0 G B^3/(1 - nu). With two elements per
    half-width the BEM is stiffer (the traction's edge singularity is under-resolved): measured 8 %
    and 27 % above, shrinking with the element size (runs/impedance/README.md); asserted here within
    10 % and 30 %, and settled (the last 30 steps agree to 1e-3)."""
    v, r = str(tmp_path / "v.h5"), str(tmp_path / "r.h5")
    args = BASE + ["-ssi_t_end", "0.08"]
    cli(args + ["-ssi_symmetry", "x=sym,y=sym", "-ssi_disp_value", "0,0,-1e-6", "-ssi_output", v], nranks=2)
    cli(args + ["-ssi_symmetry", "x=anti,y=sym", "-ssi_disp_rotation", "0,1e-6,0", "-ssi_output", r], nranks=2)
    kz = -resultants(v)["force"][:, 2] / 1e-6
    kr = resultants(r)["moment"][:, 1] / 1e-6
    for k, ref, tol in ((kz, 4.7 * G / (1 - NU), 0.10), (kr, 4.0 * G / (1 - NU), 0.30)):
        assert np.ptp(k[-30:]) <= 1e-3 * abs(k[-1])
        assert 1.0 < k[-1] / ref < 1.0 + tol, k[-1] / ref


# slow tier: a rigid motion's resultants at -n 2 and through a restart (9 s; the square's stiffness stays)
@pytest.mark.slow
def test_two_ranks_equal_one_and_a_restart_keeps_the_resultants(tmp_path):
    """Rocking about y through x_ref on the x = 0 plane: -n 2 equals -n 1 to 1e-10, and a run
    restarted from a checkpoint writes the same resultants bit for bit."""
    from test_checkpoint import run_and_restart
    args = BASE + ["-ssi_t_end", "0.04", "-ssi_symmetry", "x=anti,y=sym", "-ssi_disp_rotation", "0,1e-6,0"]
    a, b = str(tmp_path / "a.h5"), str(tmp_path / "b.h5")
    cli(args + ["-ssi_output", a])
    cli(args + ["-ssi_output", b], nranks=2)
    A, B = resultants(a), resultants(b)
    assert np.abs(A["moment"] - B["moment"]).max() <= 1e-10 * np.abs(A["moment"]).max()
    (tmp_path / "ck").mkdir()
    (ref, rs), = run_and_restart(args, tmp_path / "ck", 1, 20, 20)
    R, S = resultants(ref), resultants(rs)
    for k in R:
        assert np.array_equal(R[k], S[k]), k


def test_a_motion_the_symmetry_contradicts_is_refused(tmp_path):
    """Rocking about y is antisymmetric about x = 0: declared symmetric, or turning about a point
    off the plane, it is refused in one line (the first on 2 ranks, where every rank must stop; the
    others on 1: the checks are the same code); a malformed vector too."""
    out = ["-ssi_output", str(tmp_path / "x.h5"), "-ssi_t_end", "0.01"]
    for extra, msg, n in ((["-ssi_symmetry", "x=sym", "-ssi_disp_rotation", "0,1e-6,0"], "is not symmetric", 2),
                          (["-ssi_symmetry", "x=anti", "-ssi_disp_rotation", "0,1e-6,0", "-ssi_disp_ref", "0.5,0,0"],
                           "is not antisymmetric", 1),
                          (["-ssi_disp_rotation", "0,1e-6"], "expected three numbers", 1)):
        p = cli(BASE + out + extra, nranks=n, check=False)
        errs = [ln for ln in p.stderr.splitlines() if ln.startswith("petsc-ssi: error: ")]
        assert p.returncode == 2 and len(errs) == 1 and msg in errs[0], (extra, p.stdout[-1500:])
