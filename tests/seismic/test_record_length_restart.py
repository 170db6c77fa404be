"""A run that lasts the record (no -ssi_t_end) restarts with the options it started with (issue 44,
found by an engineer; fixed by issue 40's time grid: the record's length makes the run's grid,
``timegrid.TimeGrid.of_run``, and nothing writes -ssi_t_end into the options, so the checkpoint's key
holds the options as given). Before, the first run wrote t_end = 0.5 into its options and so into
its checkpoint, and the restart said "-ssi_t_end is 0.04 here and was 0.5", although the stop
message suggests exactly that command. The fixed base and the soil under a record, at 1 and 2 ranks:
the restarted run equals the uninterrupted one bit for bit, and both last the record."""
import h5py
import numpy as np
import pytest

from helpers import cli
from test_checkpoint import run_and_restart, assert_same_files

pytestmark = pytest.mark.mpi

BASE = ["-ssi_seismic", "vertical", "-ssi_seismic_units", "m/s2", "-ssi_seismic_taper", "0",
        "-ssi_seismic_baseline", "none", "-ssi_output_stride", "10", "-ssi_reproducible"]
FEM = ["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2", "-ssi_fem_box_size", "1,1,1", "-ssi_fem_box_origin",
       "-0.5,-0.5,0", "-ssi_fem_E", "3e7", "-ssi_fem_rho", "2000", "-ssi_fem_fixed", "base", "-ssi_dt", "0.01",
       "-ssi_receivers", "0,0,1"]
BEM = ["-ssi_problem", "bem", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "2,2",
       "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5", "-ssi_disp_group", "box:-0.5,0.5,-0.5,0.5",
       "-ssi_disp_rigid", "massless", "-ssi_dt", "0.01", "-ssi_receivers", "1,0,0", "-ssi_warn_beta", "0"]


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """0.5 s of a sin^4 pulse and its reverse (returns to rest), 100 Hz, m/s^2."""
    t = np.arange(0.0, 0.5 + 1e-9, 0.01)
    a = np.where(t < 0.2, np.sin(np.pi * t / 0.2) ** 4, 0.0) - np.where((t >= 0.2) & (t < 0.4),
                                                                        np.sin(np.pi * (t - 0.2) / 0.2) ** 4, 0.0)
    p = tmp_path_factory.mktemp("rec") / "pulse.txt"
    np.savetxt(p, np.c_[t, a])
    return str(p)


# slow tier: the fixed base on two ranks (7-9 s); the fixed base on one rank and the soil on two stay
@pytest.mark.parametrize("case,nranks", [("fixed base", 1), pytest.param("fixed base", 2, marks=pytest.mark.slow),
                                         ("soil", 2)])
def test_a_run_that_lasts_the_record_restarts_with_its_own_options(case, nranks, record, tmp_path):
    args = (FEM if case == "fixed base" else BEM) + BASE + ["-ssi_seismic_record", record]
    (ref, rs), = run_and_restart(args, tmp_path, nranks, 20, 20)
    assert_same_files(rs, ref)
    with h5py.File(ref) as f:
        t = f["receivers/t"][...]
        assert np.abs(f["receivers/u"][...]).max() > 0
    assert t[-1] >= 0.5 - 1e-12 and len(t) > 40                     # the run lasted the record


def test_the_options_keep_what_the_user_gave_and_the_record_says_the_grid(record, tmp_path):
    import json
    out = tmp_path / "f.h5"
    cli(FEM + BASE + ["-ssi_seismic_record", record, "-ssi_output", str(out)])
    rec = json.load(open(tmp_path / "f.json"))
    from petsc_ssi.options import options
    import petsc_ssi.app.kinds  # noqa: F401  (every option declared)
    assert rec["options"]["t_end"] == options()["t_end"].default          # as given: not set
    grid = rec["time_grid"]
    assert grid["n_steps"] >= 50 and grid["t_end_s"] >= 0.5 - 1e-12 and grid["dt_s"] == 0.01
