"""The coupled run through the command line: mpirun -n 2 reproduces -n 1
(unilateral, with lift-off), and bad input ends with one line on every rank
before any assembly."""
import h5py
import numpy as np
import pytest

from helpers import cli

pytestmark = pytest.mark.mpi

CASE = ["-ssi_problem", "ssi", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800",
        "-ssi_mesh_size", "2,2", "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5",
        "-ssi_fem_box_cells", "4,4,2", "-ssi_fem_box_size", "1,1,0.5", "-ssi_fem_load_group", "top_left,top_right:-1",
        "-ssi_fem_load_p0", "1000", "-ssi_fem_load_history", "box", "-ssi_dt", "0.0125", "-ssi_t_end", "0.2",
        "-ssi_contact", "unilateral", "-ssi_contact_cohesion", "300", "-ssi_output_stride", "4",
        "-ssi_receivers", "1,0,0", "-ssi_structure_receivers", "0.5,0,0.5", "-ssi_warn_beta", "0"]


def _read(path):
    with h5py.File(path, "r") as f:
        return {k: f["interface"][k][:] for k in f["interface"]}, f["receivers/u"][:]


def test_two_ranks_reproduce_one(tmp_path):
    out = {}
    for n in (1, 2):
        path = tmp_path / f"n{n}.h5"
        cli(CASE + ["-ssi_output", str(path)], nranks=n)
        out[n] = _read(path)
        with h5py.File(tmp_path / f"n{n}_structure.h5", "r") as f:
            out[n] += (f["receivers/u"][:],)
    (i1, s1, st1), (i2, s2, st2) = out[1], out[2]
    assert i1["n_open"].max() > 0                       # the case exercises the contact
    assert np.array_equal(i1["closed"], i2["closed"])
    for k in ("uf", "ub", "p", "gap"):
        scale = np.abs(i1[k]).max()
        assert np.abs(i1[k] - i2[k]).max() <= 1e-9 * scale, k
    assert np.abs(s1 - s2).max() <= 1e-9 * np.abs(s1).max()
    assert np.abs(st1 - st2).max() <= 1e-9 * np.abs(st1).max()


@pytest.mark.parametrize("extra, msg", [
    (["-ssi_symmetry", "x=anti"], "contact destroys the antisymmetry"),
    (["-ssi_fem_box_cells", "5,5,2"], "no soil element has all nine nodes"),
    (["-ssi_fem_interface", "bottom"], "no face group 'bottom'"),
    (["-ssi_fem_integrator", "green"], "-ssi_coupling implicit integrates the structure with the trapezoidal rule"),
    (["-ssi_disp_group", "load"], "-ssi_disp_group prescribes soil displacements"),
])
def test_bad_input_one_line_every_rank(tmp_path, extra, msg):
    p = cli(CASE + ["-ssi_output", str(tmp_path / "x.h5")] + extra, nranks=2, check=False)
    assert p.returncode == 2, p.stdout + p.stderr
    lines = [l for l in p.stderr.splitlines() if l.startswith("petsc-ssi: error:")]
    assert len(lines) == 1 and msg in lines[0], p.stdout
    assert "assembly" not in p.stdout
