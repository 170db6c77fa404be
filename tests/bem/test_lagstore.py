"""Reusable lag matrices (issue 14, item 3; petsc_ssi/bem/lagstore.py): -ssi_lags_save writes the
step matrix, the lags and the interpolating matrices with the key of what they depend on;
-ssi_lags_load uses them instead of assembling. A run with loaded matrices is bitwise the run that
assembled them (one rank; on another rank count to round-off), what the matrices do not depend on
(the load, the structure) may change, and a changed key is refused in one line naming it."""
import json

import h5py
import numpy as np

from helpers import cli
import pytest

pytestmark = pytest.mark.mpi

BEM = ["-ssi_problem", "bem", "-ssi_mesh_size", "12,12", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
       "-ssi_symmetry", "x=sym,y=sym", "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.0025",
       "-ssi_t_end", "0.15", "-ssi_receivers", "3,0,0;0,0,0", "-ssi_output_stride", "20", "-ssi_warn_beta", "0",
       "-ssi_interp", "linear", "-ssi_interp_tl", "0.01", "-ssi_interp_k", "3"]
SSI = ["-ssi_problem", "ssi", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "2,2",
       "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5", "-ssi_fem_box_cells", "4,4,1", "-ssi_fem_box_size",
       "1,1,0.25", "-ssi_fem_box_origin", "-0.5,-0.5,0", "-ssi_fem_E", "300e9", "-ssi_fem_rho", "200",
       "-ssi_dt", "0.0125", "-ssi_t_end", "0.5", "-ssi_fem_load_group", "top", "-ssi_fem_load_p0", "1000",
       "-ssi_fem_load_history", "box", "-ssi_fem_load_t0", "0.05", "-ssi_contact", "unilateral",
       "-ssi_receivers", "1,0,0", "-ssi_output_stride", "10", "-ssi_warn_beta", "0"]


def fields(path, keys=("receivers/u", "displacement_000002", "traction_000002")):
    with h5py.File(path) as f:
        return {k: f[k][:] for k in keys}


# slow tier: the make-test budget (10-20 s); the default tier's sibling: test_a_restart_with_loaded_lags_is_bitwise
@pytest.mark.slow
def test_loaded_lags_give_the_assembled_run_bitwise(tmp_path):
    """Saved by one run, loaded by a run with twice the load: u is exactly twice the first run's
    (the solution is linear and scaling by 2 is exact in floating point) and bitwise the run
    that assembles its own matrices with that load; loaded on 2 ranks, the same to 1e-12."""
    lags = str(tmp_path / "soil.lags")
    a, b, c, d = (str(tmp_path / f"{k}.h5") for k in "abcd")
    r = cli(BEM + ["-ssi_output", a, "-ssi_lags_save", lags])
    assert "lag matrices saved to" in r.stdout
    man = json.load(open(lags + ".json"))
    assert [k for _, k in man["mats"]][:1] == ["aij"] and len(man["mats"]) == 1 + 2 * 4 + 2 * 3
    r = cli(BEM + ["-ssi_output", b, "-ssi_lags_load", lags, "-ssi_load_p0", "2000"])
    assert "loaded from" in r.stdout and "kernel evaluations" not in r.stdout
    cli(BEM + ["-ssi_output", c, "-ssi_load_p0", "2000"])
    A, B, C = fields(a), fields(b), fields(c)
    for k in A:
        assert np.abs(A[k]).max() > 0
        assert np.array_equal(B[k], 2.0 * A[k]), k
        assert np.array_equal(B[k], C[k]), k
    cli(BEM + ["-ssi_output", d, "-ssi_lags_load", lags], nranks=2)
    D = fields(d)
    for k in A:
        assert np.abs(D[k] - A[k]).max() <= 1e-12 * np.abs(A[k]).max(), k


# slow tier: a coupled study reusing the soil's lags (14 s; sibling in make test:
# test_loaded_lags_give_the_assembled_run_bitwise)
@pytest.mark.slow
def test_a_coupled_study_reuses_the_soil(tmp_path):
    """The block on the half-space with contact: the soil's matrices saved once, loaded by a run
    with a softer, heavier block (the structure is not in the key): bitwise the assembled run."""
    lags = str(tmp_path / "soil.lags")
    cli(SSI + ["-ssi_output", str(tmp_path / "a.h5"), "-ssi_lags_save", lags])
    other = ["-ssi_fem_E", "3e8", "-ssi_fem_rho", "2000"]
    cli(SSI + other + ["-ssi_output", str(tmp_path / "b.h5"), "-ssi_lags_load", lags])
    cli(SSI + other + ["-ssi_output", str(tmp_path / "c.h5")])
    keys = ("receivers/u", "interface/p", "interface/uf", "interface/closed")
    B, C, A = (fields(str(tmp_path / f"{k}.h5"), keys) for k in "bca")
    for k in keys:
        assert np.array_equal(B[k], C[k]), k
    assert not np.array_equal(A["interface/uf"], B["interface/uf"])     # the structure did change


# slow tier: the options of a lag file's key changed in turn, each refused (27 s; the checkpoint key's
#  refusals stay in make test)
@pytest.mark.slow
def test_a_changed_key_is_refused(tmp_path):
    """What the matrices depend on may not change: dt, the mesh, the symmetry, the scheme, the
    interpolation, the material; a file without its .json (a save cut short), saving and loading
    at once, and replacing a saved file without -ssi_output_overwrite are refused too: one line on
    every rank of 2, exit 2, before any assembly."""
    lags = str(tmp_path / "soil.lags")
    cli(BEM + ["-ssi_output", str(tmp_path / "a.h5"), "-ssi_lags_save", lags])
    out = ["-ssi_output", str(tmp_path / "x.h5"), "-ssi_output_overwrite"]
    cases = [(["-ssi_dt", "0.002"], "dt differs"), (["-ssi_mesh_h", "0.5"], "mesh_nodes differs"),
             (["-ssi_gauss", "3"], "quadrature_gauss differs"), (["-ssi_scheme", "plain"], "scheme differs"),
             (["-ssi_interp_k", "4"], "interp differs"), (["-ssi_cs", "300"], "cs differs"),
             (["-ssi_lags_save", str(tmp_path / "other.lags")], "-ssi_lags_save with -ssi_lags_load")]
    for extra, msg in cases:
        p = cli(BEM + out + ["-ssi_lags_load", lags] + extra, nranks=2, check=False)
        errs = [ln for ln in p.stderr.splitlines() if ln.startswith("petsc-ssi: error: ")]
        assert p.returncode == 2 and len(errs) == 1 and msg in errs[0], (extra, p.stdout[-1500:])
        assert "assembly" not in p.stdout and "Traceback" not in p.stderr
    open(str(tmp_path / "cut.lags"), "wb").write(b"\0" * 64)
    p = cli(BEM + out + ["-ssi_lags_load", str(tmp_path / "cut.lags")], nranks=2, check=False)
    assert p.returncode == 2 and "cut.lags.json is missing" in p.stderr
    p = cli(BEM + ["-ssi_output", str(tmp_path / "y.h5"), "-ssi_lags_save", lags], nranks=2, check=False)
    assert p.returncode == 2 and "add -ssi_output_overwrite" in p.stderr


def test_a_restart_with_loaded_lags_is_bitwise(tmp_path):
    """A run that saved its lags and checkpoints is restarted with -ssi_lags_load (no assembly):
    bitwise the uninterrupted run (the traction Vecs keep block size 3 either way)."""
    import shutil
    lags, ck = str(tmp_path / "soil.lags"), str(tmp_path / "ck-%d.h5")
    (tmp_path / "a").mkdir()
    a = str(tmp_path / "a" / "r.h5")
    cli(BEM + ["-ssi_output", a, "-ssi_lags_save", lags, "-ssi_checkpoint", ck, "-ssi_checkpoint_every", "25"])
    shutil.copytree(tmp_path / "a", tmp_path / "b")
    b = str(tmp_path / "b" / "r.h5")
    r = cli(BEM + ["-ssi_output", b, "-ssi_lags_load", lags, "-ssi_restart", str(tmp_path / "ck-25.h5")])
    assert "loaded from" in r.stdout and "restarted from" in r.stdout
    A, B = fields(a), fields(b)
    for k in A:
        assert np.array_equal(A[k], B[k]), k
