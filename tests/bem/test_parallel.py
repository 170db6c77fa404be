"""mpirun -n 2 reproduces -n 1 (the test launches mpirun)."""
import shutil

import numpy as np
import pytest

from helpers import cli, read_h5, relmax

pytestmark = pytest.mark.mpi

ARGS = ["-ssi_mesh_size", "8,8", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1", "-ssi_load_group", "load",
        "-ssi_load_p0", "1000", "-ssi_symmetry", "x=sym", "-ssi_t_end", "0.0075", "-ssi_dt", "7.5e-4",
        "-ssi_receivers", "3,0,0;-2,2,0", "-ssi_output_stride", "5"]


@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
@pytest.mark.parametrize("storage,extra", [
    ("auto", []), ("sparse", []),
    # prescribed displacement (the traction-unknown scatters) plus a box load
    ("auto", ["-ssi_disp_group", "box:2,3,-1,1", "-ssi_disp_value", "0,0,-1e-6",
              "-ssi_load_history", "box", "-ssi_load_t0", "0.003"]),
    ("auto", ["-ssi_interp", "chebyshev", "-ssi_interp_tl", "0.003", "-ssi_interp_k", "3"]),
])
def test_two_ranks_reproduce_one(tmp_path, storage, extra):
    a, b = tmp_path / "n1.h5", tmp_path / "n2.h5"
    cli(ARGS + extra + ["-ssi_lag_storage", storage, "-ssi_output", str(a)], nranks=1)
    cli(ARGS + extra + ["-ssi_lag_storage", storage, "-ssi_output", str(b)], nranks=2)
    r1, r2 = read_h5(a), read_h5(b)
    assert np.abs(r1["u"]).max() > 0
    assert relmax(r2["u"], r1["u"]) <= 1e-10
    assert relmax(r2["last"], r1["last"]) <= 1e-10


def _evaluations(p):
    import re
    m = re.search(r"([0-9.e+]+) kernel evaluations", p.stdout)
    assert m, p.stdout
    return float(m.group(1))


@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
def test_shared_element_cache(tmp_path):
    """-ssi_cache_share (default): on 2 ranks every distinct pair geometry is integrated once over both
    ranks, so the kernel evaluations summed over the ranks are no more than one rank's (the per-rank
    caches of -ssi_cache_share 0 integrate the geometries both ranks meet twice: more than one rank), and the
    solution equals -n 1 to 1e-12 (the owner integrates the representative a single rank meets first),
    with a traction-unknown (G) region so that the displacement-kernel blocks travel too."""
    extra = ["-ssi_disp_group", "box:2,3,-1,1", "-ssi_disp_value", "0,0,-1e-6"]
    out = {k: tmp_path / f"{k}.h5" for k in ("n1", "shared", "own")}
    p1 = cli(ARGS + extra + ["-ssi_output", str(out["n1"])], nranks=1)
    ps = cli(ARGS + extra + ["-ssi_output", str(out["shared"])], nranks=2)
    po = cli(ARGS + extra + ["-ssi_output", str(out["own"]), "-ssi_cache_share", "0"], nranks=2)
    e1, es, eo = _evaluations(p1), _evaluations(ps), _evaluations(po)
    assert es <= e1 < eo, (e1, es, eo)
    r1, rs, ro = (read_h5(out[k]) for k in ("n1", "shared", "own"))
    assert np.abs(r1["u"]).max() > 0
    assert relmax(rs["u"], r1["u"]) <= 1e-12 and relmax(rs["last"], r1["last"]) <= 1e-12
    assert relmax(ro["u"], r1["u"]) <= 1e-10
