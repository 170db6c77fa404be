"""-ssi_step_blr: the soil's step matrix factorised by MUMPS in block low-rank form (bem/march.py). The
factors are checked on a fixed right-hand side before the run uses them; the answer equals the full-rank
LU's to round-off of the chosen precision; a check that fails falls back to full rank, said in one line."""
import os
import sys

import numpy as np
import pytest

from helpers import cli, run_bem

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_history_block import BEM, SSI, same  # noqa: E402

pytestmark = pytest.mark.mpi


def test_step_blr_coupled_contact_equals_full_rank(tmp_path):
    """The coupled box with unilateral contact on the toeplitz store: the step matrix's LU block low-rank at
    1e-15 against full rank, every recorded field to 1e-12 of its kind's largest value; the log says so and
    gives the test residual; the automatic choice keeps this small matrix (below 20 000 DOFs) in full rank."""
    ref, blr = str(tmp_path / "full.h5"), str(tmp_path / "blr.h5")
    TZ = ["-ssi_lag_store", "toeplitz"]
    out0 = cli(SSI + TZ + ["-ssi_output", ref]).stdout
    assert "block low-rank" not in out0
    out = cli(SSI + TZ + ["-ssi_step_blr", "1e-15", "-ssi_output", blr]).stdout
    line = [ln for ln in out.splitlines() if "[ssi] step matrix:" in ln][0]
    assert "block low-rank at eps 1e-15 (-ssi_step_blr; test residual" in line, line
    assert float(line.rsplit("test residual ", 1)[1].rstrip(")")) <= 1e-12
    same(ref, blr, rtol=1e-12)


def test_step_blr_two_ranks_dense_path(tmp_path):
    """The dense lag store at -n 2 with the block low-rank LU (1e-15) against full rank at -n 1: to 1e-12."""
    ref, blr = str(tmp_path / "full.h5"), str(tmp_path / "blr.h5")
    cli(BEM + ["-ssi_step_blr", "0", "-ssi_output", ref])
    out = cli(BEM + ["-ssi_step_blr", "1e-15", "-ssi_output", blr], nranks=2).stdout
    assert "block low-rank at eps 1e-15" in out
    same(ref, blr, rtol=1e-12)


def test_step_blr_check_falls_back_to_full_rank(tmp_path, monkeypatch, capfd):
    """A block low-rank LU whose test residual exceeds the bound (the bound set below any residual here) is
    replaced by the full-rank LU, said in one line, and the run's answer is the full-rank one's, bit for bit."""
    from petsc_ssi.bem import march
    monkeypatch.setattr(march, "BLR_FROM", 0)          # (auto takes BLR on this small grid)
    monkeypatch.setattr(march, "BLR_TOL", -1.0)        # (no residual passes)
    kw = dict(mesh_size="6,6", mesh_h=1.0, mesh_patch="1,1", load_group="load", load_p0=1000, dt=0.0025,
              t_end=0.02, receivers="0,0,0;2,0,0", output_stride=0, warn_beta=0, step_mirror="off")
    a = run_bem(**kw, output=tmp_path / "a.h5")
    out = capfd.readouterr().out
    assert "left a residual" in out and "factorised in full rank instead (-ssi_step_blr)" in out, out[-3000:]
    monkeypatch.setattr(march, "BLR_FROM", 10 ** 9)    # (auto: full rank)
    b = run_bem(**kw, output=tmp_path / "b.h5")
    assert "block low-rank" not in capfd.readouterr().out
    assert np.abs(a["u"]).max() > 0 and np.array_equal(a["u"], b["u"])


def test_step_blr_option_refuses_bad_values(tmp_path):
    r = cli(BEM + ["-ssi_step_blr", "0.5", "-ssi_output", str(tmp_path / "x.h5")], check=False)
    assert r.returncode != 0 and "-ssi_step_blr" in (r.stdout + r.stderr) and "must be -1" in (r.stdout + r.stderr)


def test_step_blr_asked_for_but_the_user_sets_mumps(tmp_path):
    """-ssi_step_blr with the user's own -ssi_bem_mat_mumps_icntl_35: their options decide, said in one line."""
    out = cli(BEM + ["-ssi_t_end", "0.01", "-ssi_step_blr", "1e-15", "-ssi_bem_mat_mumps_icntl_35", "0",
                     "-ssi_output", str(tmp_path / "x.h5")]).stdout
    assert "-ssi_step_blr 1e-15: the step matrix is not factorised by MUMPS's LU here, or" in out
    assert "block low-rank at eps" not in out
