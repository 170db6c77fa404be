"""Nothing lost, nothing silent, round three (issue 44): refused late or for the wrong cause.

  * a run that lasts the record (no -ssi_t_end: t_end is the record's length) restarts with the
    same options, as its stop message says (before: '-ssi_t_end is 0.04 here and was 0.06'); giving
    the derived value is the same run, another value is refused naming both;
  * -ssi_seismic_format table on a restart of a run whose record 'auto' found as a table is the same
    run (before: refused as a change); another format is still refused;
  * a restart whose output lost a part (a linked dataset's file) is refused before the assembly
    (before: after it).
"""
import os
import shutil

import numpy as np
import pytest

from helpers import cli
from test_integrity import SMALL, refused, files

pytestmark = pytest.mark.mpi


def _fem(tmp_path):
    t = np.arange(0.0, 0.06, 0.005)
    rec = str(tmp_path / "short.txt")
    np.savetxt(rec, np.c_[t, np.sin(2 * np.pi * 10 * t)], header="units: m/s2")
    return ["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2", "-ssi_fem_fixed", "base", "-ssi_dt", "0.005",
            "-ssi_seismic", "vertical", "-ssi_seismic_record", rec, "-ssi_seismic_taper", "0",
            "-ssi_seismic_baseline", "none"]


@pytest.fixture(scope="module")
def record_run(tmp_path_factory):
    """A fixed base that lasts its record (no -ssi_t_end: 12 steps), checkpoints every 4 steps."""
    d = tmp_path_factory.mktemp("record")
    A = _fem(d)
    cli(A + ["-ssi_output", str(d / "a.h5"), "-ssi_checkpoint", str(d / "ck-%d.h5"), "-ssi_checkpoint_every", "4"])
    return d, A


# slow tier: the two-rank restart (9-10 s); the one-rank restart stays in make test
@pytest.mark.parametrize("n", [1, pytest.param(2, marks=pytest.mark.slow)])
def test_a_run_that_lasts_the_record_restarts_with_its_own_options(record_run, tmp_path, n):
    d, A = record_run
    a, ck = str(d / "a.h5"), str(d / "ck-4.h5")
    for i, extra in enumerate(([], ["-ssi_t_end", "0.06", "-ssi_seismic_format", "table"])[:2 if n == 1 else 1]):
        b = str(tmp_path / f"b{i}.h5")
        shutil.copy(a, b)
        r = cli(A + extra + ["-ssi_output", b, "-ssi_restart", ck], nranks=n)
        assert "restarted from" in r.stdout and "after step 4 of 12" in r.stdout, r.stdout[-2000:]
    for extra, msg in ((["-ssi_t_end", "0.05"], "-ssi_t_end is 0.05 here and was 0.06 (not given: the record's "
                                                 "length); leave -ssi_t_end out"),
                       (["-ssi_seismic_format", "peer"], "-ssi_seismic_format is peer here and was table")):
        err = refused(cli(A + extra + ["-ssi_output", str(tmp_path / "b0.h5"), "-ssi_restart", ck], nranks=n,
                          check=False))
        assert msg in err, err


@pytest.mark.parametrize("n", [1, 2])
def test_a_restart_whose_output_lost_a_part_is_refused_before_the_assembly(tmp_path, n):
    out = str(tmp_path / "r.h5")
    cli(SMALL + ["-ssi_output", out, "-ssi_output_merge", "0", "-ssi_output_flush", "0",
                 "-ssi_checkpoint", str(tmp_path / "ck-%d.h5"), "-ssi_checkpoint_every", "4"])
    parts = sorted(os.listdir(tmp_path / "r.parts"))
    assert parts
    os.remove(tmp_path / "r.parts" / parts[0])
    before = files(tmp_path)
    r = cli(SMALL + ["-ssi_output", out, "-ssi_restart", str(tmp_path / "ck-4.h5")], nranks=n, check=False)
    err = refused(r)
    assert f"-ssi_output {out} links its dataset" in err and "which is missing" in err, err
    assert "lag interpolation" not in r.stdout and "assembl" not in r.stdout.lower(), r.stdout[-2000:]
    assert files(tmp_path) == before
