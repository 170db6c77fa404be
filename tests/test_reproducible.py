"""Reruns at a fixed rank count (issue 14): with -ssi_reproducible, two runs of the same FEM or
BEM case at -n 2 are bitwise identical (the direct solves use SuperLU_dist; with MUMPS, reruns
may differ at round-off: jobscripts/rerun_determinism.sh). Coupled runs refuse the option in one
line (two SuperLU_dist factorisations in one process crash PETSc 3.18's build at exit)."""
import h5py
import numpy as np
import pytest

from helpers import cli

FEM = ["-ssi_problem", "fem", "-ssi_fem_box_cells", "3,3,3", "-ssi_fem_fixed", "base", "-ssi_fem_load_group", "top",
       "-ssi_fem_load_p0", "1000", "-ssi_fem_load_history", "box", "-ssi_fem_load_t0", "0.01", "-ssi_dt", "1e-3",
       "-ssi_t_end", "0.05", "-ssi_receivers", "0.5,0.5,0.5", "-ssi_output_stride", "10"]
BEM = ["-ssi_problem", "bem", "-ssi_mesh_size", "4,4", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
       "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.005", "-ssi_t_end", "0.1",
       "-ssi_receivers", "2,0,0", "-ssi_output_stride", "10", "-ssi_monitor", "-ssi_warn_beta", "0"]


@pytest.mark.parametrize("case", ["fem", "bem"])
def test_reruns_are_bitwise_identical(case, tmp_path):
    res = []
    for k in range(2):
        out = str(tmp_path / f"r{k}.h5")
        r = cli({"fem": FEM, "bem": BEM}[case] + ["-ssi_output", out, "-ssi_reproducible"], nranks=2)
        assert "pc_factor_mat_solver_type superlu_dist" in r.stdout
        with h5py.File(out) as f:
            res.append({k: f[k][:] for k in ("receivers/u", "displacement_000001")})
    for k in res[0]:
        assert np.array_equal(res[0][k], res[1][k]), k
        assert np.abs(res[0][k]).max() > 0


def test_coupled_runs_refuse_the_option(tmp_path):
    r = cli(["-ssi_problem", "ssi", "-ssi_reproducible", "-ssi_output", str(tmp_path / "x.h5")], nranks=2,
            check=False)
    errs = [ln for ln in r.stdout.splitlines() if ln.startswith("petsc-ssi: error: ")]
    assert r.returncode == 2 and len(errs) == 1 and "-ssi_reproducible is for -ssi_problem bem and fem" in errs[0]
