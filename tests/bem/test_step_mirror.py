"""-ssi_step_mirror: the step matrix of a mirror-symmetric soil surface factorised as its independent symmetric
and antisymmetric blocks (bem/mirror.py). The answer equals the LU of the matrix as it is to 1e-12 of each
field's scale (a load off the mirror lines too: the load is a right-hand side, not the matrix), on the dense and
the toeplitz stores, at -n 1 and -n 2, for a rigid footing (traction unknowns) and the coupled box with contact
(its interface columns through the same blocks); a footing off the centre in one direction mirrors about the
other plane only; one whose prescribed nodes do not mirror keeps the matrix as it is; the log says which."""
import os
import sys

import numpy as np
import pytest

from helpers import cli, run_bem

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_history_block import BEM, DISP, SSI, same  # noqa: E402

pytestmark = pytest.mark.mpi

OFF = ["-ssi_step_mirror", "off"]


def _line(out):
    return [ln for ln in out.splitlines() if "[ssi] step matrix:" in ln][0]


@pytest.mark.parametrize("store,nranks", [("dense", 1), ("toeplitz", 2)])
def test_rigid_footing_off_centre_load_equals_the_matrix_as_it_is(tmp_path, store, nranks):
    """A rigid footing centred on the grid (prescribed motion: traction unknowns, both mirror planes) with a
    load patch beside it (not symmetric): four blocks, every field to 1e-12 of its scale."""
    case = DISP + ["-ssi_lag_store", store, "-ssi_load_group", "box:1.5,2.5,0.5,1.5", "-ssi_load_p0", "1000",
                   "-ssi_load_history", "box", "-ssi_load_t0", "0.01"]
    ref, got = str(tmp_path / "ref.h5"), str(tmp_path / "got.h5")
    out0 = cli(case + OFF + ["-ssi_output", ref]).stdout
    assert "mirror" not in _line(out0)
    out = cli(case + ["-ssi_output", got], nranks=nranks).stdout
    line = _line(out)
    assert "mirror-symmetric about x = 0 and y = 0: 4 independent blocks of" in line, line
    res = float(line.rsplit("test residual ", 1)[1].rstrip(")"))
    assert 0.0 <= res <= 1e-12
    same(ref, got, rtol=1e-12)


def test_off_centre_footing_mirrors_about_one_plane(tmp_path):
    """A rigid footing beside the grid's centre, symmetric about y = 0 only: two blocks (the dense store at
    -n 2), every field to 1e-12 of its scale."""
    case = DISP[:]
    case[case.index("load")] = "box:0.5,1.5,-0.5,0.5"
    ref, got = str(tmp_path / "ref.h5"), str(tmp_path / "got.h5")
    cli(case + OFF + ["-ssi_output", ref])
    out = cli(case + ["-ssi_output", got], nranks=2).stdout
    assert "mirror-symmetric about y = 0: 2 independent blocks of" in _line(out), _line(out)
    same(ref, got, rtol=1e-12)


def test_coupled_box_with_contact_and_region_columns(tmp_path):
    """The coupled box with unilateral contact on the toeplitz store: the step solves and the interface columns
    through the blocks at -n 2, against the matrix as it is at -n 1, to 1e-12 until contact's first change of
    status and 1e-9 after it (a lift-off amplifies round-off, MUMPS's parallel sums among it: the module docstring
    of tests/coupling/test_region_columns.py; one run of this test came to 1.06e-12 over the whole run)."""
    import h5py
    from test_history_block import fields, scales
    TZ = ["-ssi_lag_store", "toeplitz", "-ssi_t_end", "0.25"]
    ref, got = str(tmp_path / "ref.h5"), str(tmp_path / "got.h5")
    cli(SSI + TZ + OFF + ["-ssi_output", ref])
    out = cli(SSI + TZ + ["-ssi_output", got], nranks=2).stdout
    assert "independent blocks" in _line(out), _line(out)
    same(ref, got, rtol=1e-9)
    with h5py.File(got) as f:
        closed = f["interface/closed"][...]
    changed = np.flatnonzero((closed[1:] != closed[:-1]).any(axis=1))
    first = int(changed[0]) + 1 if changed.size else len(closed)
    assert first >= 3
    A, B = fields(ref), fields(got)
    S = scales(A)
    for k in ("interface/p", "interface/ub", "interface/uf"):
        assert np.abs(A[k][:first] - B[k][:first]).max() <= 1e-12 * S[k], k


def test_prescribed_nodes_that_do_not_mirror_keep_the_matrix(tmp_path):
    """A rigid footing off the grid's centre in x and y: its prescribed nodes do not mirror, so no blocks
    (nothing said beyond the usual line), while the same footing centred has them; -ssi_step_mirror takes auto
    and off only."""
    case = DISP[:]
    case[case.index("load")] = "box:0.5,1.5,0,0.5"
    out = cli(case + ["-ssi_t_end", "0.01", "-ssi_output", str(tmp_path / "x.h5")]).stdout
    assert "mirror" not in out and "[ssi] step matrix:" in out
    out = cli(DISP + ["-ssi_t_end", "0.01", "-ssi_output", str(tmp_path / "z.h5")]).stdout
    assert "4 independent blocks" in _line(out)
    r = cli(BEM + ["-ssi_step_mirror", "on", "-ssi_output", str(tmp_path / "y.h5")], check=False)
    assert r.returncode != 0 and "-ssi_step_mirror" in (r.stdout + r.stderr)


def test_region_columns_through_the_blocks(tmp_path):
    """The bonded footing on the 28 m grid (tests/coupling/test_region_columns.py): the interface columns on the
    region around it with the region's own LU in mirror-symmetric blocks (the log says so), against the matrices
    as they are, at -n 2, to 1e-12."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "coupling"))
    from test_region_columns import BIG
    case = BIG + ["-ssi_contact", "bonded", "-ssi_t_end", "0.25"]
    ref, got = str(tmp_path / "ref.h5"), str(tmp_path / "got.h5")
    out0 = cli(case + OFF + ["-ssi_output", ref], nranks=2).stdout
    assert "mirror" not in out0
    out = cli(case + ["-ssi_output", got], nranks=2).stdout
    assert "their own LU (mirror-symmetric blocks, as the step matrix)" in out, out[-3000:]
    assert "independent blocks" in _line(out)
    same(ref, got, rtol=1e-12)


def test_blocks_that_fail_their_test_put_the_matrix_back(tmp_path, monkeypatch, capfd):
    """Blocks whose test residual exceeds the bound (the bound set below any residual) are replaced by the LU of
    the matrix as it is, said in one line, and the answer is -ssi_step_mirror off's bit for bit; a user's
    iterative solver keeps the matrix as it is without trying the blocks."""
    from petsc_ssi.bem import march
    kw = dict(mesh_size="6,6", mesh_h=1.0, mesh_patch="1,1", load_group="load", load_p0=1000, dt=0.0025,
              t_end=0.02, receivers="0,0,0;2,0,0", output_stride=0, warn_beta=0)
    monkeypatch.setattr(march, "BLR_TOL", -1.0)        # (no residual passes)
    a = run_bem(**kw, output=tmp_path / "a.h5")
    out = capfd.readouterr().out
    assert "its mirror-symmetric blocks left a residual" in out and "factorised as it is instead" in out, out[-3000:]
    assert "independent blocks" not in out
    b = run_bem(**kw, step_mirror="off", output=tmp_path / "b.h5")
    assert np.abs(a["u"]).max() > 0 and np.array_equal(a["u"], b["u"])
    capfd.readouterr()
    out = cli(BEM + ["-ssi_t_end", "0.01", "-ssi_bem_ksp_type", "gmres", "-ssi_bem_pc_type", "lu",
                     "-ssi_output", str(tmp_path / "c.h5")]).stdout
    assert "mirror" not in out
