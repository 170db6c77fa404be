"""Nothing lost, nothing silent, round three (issue 44): files lost.

Every refusal: ONE line 'petsc-ssi: error: ...', exit status 2, no traceback, no step taken, the
files that existed untouched (``refused`` and ``files`` of tests/test_integrity.py).

  * a second run with another run's '%d' checkpoint pattern is refused (before: it replaced
    ck-2.h5, ck-4.h5 of the first run step by step); a restart replaces its own run's;
  * a checkpoint or lag file that IS the output through a symbolic link (to the file, or to its
    directory) is refused even with -ssi_output_overwrite (before: names compared by abspath, the
    output destroyed, exit status 0);
  * input-motion refuses to replace an existing <stem>-input-motion.csv / .png without
    -ssi_output_overwrite, and refuses -ssi_output '' (before: it wrote into ./out/).
"""
import os

import pytest

from helpers import cli
from test_integrity import SMALL, refused, files

pytestmark = pytest.mark.mpi


@pytest.fixture(scope="module")
def numbered(tmp_path_factory):
    """Run A's output and its checkpoints ck-2.h5, ck-4.h5 (made once, copied by each test)."""
    d = tmp_path_factory.mktemp("numbered")
    cli(SMALL + ["-ssi_output", str(d / "a.h5"), "-ssi_checkpoint", str(d / "ck-%d.h5"), "-ssi_checkpoint_every", "2"])
    assert os.path.exists(d / "ck-2.h5") and os.path.exists(d / "ck-4.h5")
    return d


# slow tier: the two-rank case (5-9 s); the one-rank case stays in make test
@pytest.mark.parametrize("n", [1, pytest.param(2, marks=pytest.mark.slow)])
def test_another_runs_numbered_checkpoints_are_not_replaced(numbered, tmp_path, n):
    import shutil
    run = tmp_path / "run"
    shutil.copytree(numbered, run)
    ck = str(run / "ck-%d.h5")
    before = files(run)
    err = refused(cli(SMALL + ["-ssi_output", str(run / "b.h5"), "-ssi_checkpoint", ck,
                               "-ssi_checkpoint_every", "2"], nranks=n, check=False))
    assert f"-ssi_checkpoint {ck}: {run / 'ck-2.h5'} exists and is not this run's" in err, err
    assert "-ssi_output_overwrite" in err
    assert files(run) == before
    if n == 1:
        # a restart of the run that wrote them replaces its own (the same run id)
        r = cli(SMALL + ["-ssi_output", str(run / "a.h5"), "-ssi_checkpoint", ck, "-ssi_checkpoint_every", "2",
                         "-ssi_restart", str(run / "ck-2.h5")], nranks=n)
        assert "restarted from" in r.stdout


# slow tier: the two-rank case (5-9 s); the one-rank case stays in make test
@pytest.mark.parametrize("n", [1, pytest.param(2, marks=pytest.mark.slow)])
def test_a_checkpoint_or_lag_file_that_is_the_output_through_a_link_is_refused(numbered, tmp_path, n):
    import shutil
    run = tmp_path / "run"
    run.mkdir()
    out = str(run / "o.h5")
    for f in ("a.h5", "a.json", "a.xmf"):
        shutil.copy(numbered / f, run / f.replace("a.", "o."))
    os.symlink(str(run), str(tmp_path / "alias"))                 # a linked directory
    os.symlink(out, str(run / "link.h5"))                        # a link to the file
    alias = str(tmp_path / "alias" / "o.h5")
    before = files(run)
    ow = SMALL + ["-ssi_output", out, "-ssi_output_overwrite"]
    cases = [(["-ssi_checkpoint", alias, "-ssi_checkpoint_every", "2"], f"-ssi_checkpoint {alias}: would replace"),
             (["-ssi_lags_save", alias], f"-ssi_lags_save {alias}: would replace"),
             (["-ssi_lags_save", str(run / "link.h5")], "-ssi_lags_save"),
             (["-ssi_lags_save", str(tmp_path / "alias" / "o.xmf")], "a sidecar of the output")]
    for extra, msg in cases[n - 1::2]:          # (the checks are replicated: half the cases at each rank count)
        err = refused(cli(ow + extra, nranks=n, check=False))
        assert msg in err and "a name of its own" in err, (extra, err)
        assert files(run) == before, extra


def _im_args(tmp_path):
    import numpy as np
    t = np.arange(0.0, 0.2 + 1e-9, 0.1 / 80)
    a = np.where(t < 0.1, np.sin(np.pi * t / 0.1) ** 4, 0.0)
    rec = str(tmp_path / "p.txt")
    np.savetxt(rec, np.c_[t, a], header="units: m/s2")
    return ["input-motion", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "2,2",
            "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5", "-ssi_disp_group", "box:-0.5,0.5,-0.5,0.5",
            "-ssi_dt", "0.006", "-ssi_seismic", "vertical", "-ssi_seismic_record", rec, "-ssi_seismic_units",
            "m/s2", "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none", "-ssi_output_stride", "0",
            "-ssi_t_end", "0.03"]


# slow tier: the two-rank case (5-9 s); the one-rank case stays in make test
@pytest.mark.parametrize("n", [1, pytest.param(2, marks=pytest.mark.slow)])
def test_input_motion_replaces_no_file_of_the_user(tmp_path, n):
    args = _im_args(tmp_path)
    out = str(tmp_path / "im.h5")
    for side in ("-input-motion.csv", "-input-motion.png"):
        mine = tmp_path / ("im" + side)
        mine.write_text("the user's own file\n")
        err = refused(cli(args + ["-ssi_output", out], nranks=n, check=False))
        assert f"{mine} exists" in err and "-ssi_output_overwrite" in err, err
        assert mine.read_text() == "the user's own file\n" and not os.path.exists(out)
        mine.unlink()
    err = refused(cli(args + ["-ssi_output", ""], nranks=n, check=False))
    assert "-ssi_output '': petsc-ssi input-motion keeps its results in files" in err, err
