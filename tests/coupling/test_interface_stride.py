"""-ssi_interface_stride (issue 28, long records): the interface's nodal series are kept every
k steps and equal the every-step run's at those steps (bit for bit: the stride only chooses what
is kept); the resultants and open-node counts stay per step; the output file holds the nodal
steps and times."""
import h5py
import numpy as np

from helpers import run_ssi
import pytest

pytestmark = pytest.mark.run

CASE = dict(cp=42.0, cs=20.0, rho=1800.0, mesh_size="2,2", mesh_h=0.5, mesh_patch="0.5,0.5",
            fem_box_cells="4,4,1", fem_box_size="1,1,0.25", fem_box_origin="-0.5,-0.5,0", fem_E=300e9,
            fem_rho=200, dt=0.0125, t_end=0.2, output_stride=0, warn_beta=0, fem_load_group="top",
            fem_load_p0=1000, fem_load_history="box", contact="unilateral", contact_cohesion=300)


def test_stride_keeps_every_kth_step(tmp_path):
    a = run_ssi(**CASE, output=str(tmp_path / "a.h5"))["interface"]
    b = run_ssi(**CASE, output=str(tmp_path / "b.h5"), interface_stride=3)["interface"]
    n = len(a["t"])
    assert n == 16 and len(b["t"]) == n
    steps = np.arange(3, n + 1, 3)
    assert np.array_equal(b["nodal_steps"], steps)
    assert np.allclose(b["t_nodal"], steps * CASE["dt"], rtol=0, atol=1e-12)
    for k in ("uf", "ub", "p", "gap", "pN", "closed"):
        assert b[k].shape[0] == len(steps), k
        assert np.array_equal(b[k], a[k][steps - 1]), k
    for k in ("force_fe", "force_be", "iterations", "changes", "n_open"):
        assert np.array_equal(b[k], a[k]), k
    assert a["n_open"].max() > 0                               # the case lifts off
    assert np.array_equal(a["n_open"], (~a["closed"]).sum(axis=1))
    with h5py.File(tmp_path / "b.h5", "r") as f:
        assert f["interface/uf"].shape == (len(steps), a["uf"].shape[1], 3)
        assert np.array_equal(f["interface/nodal_steps"][:], steps)
        assert f["interface/force_fe"].shape == (n, 3)
