"""The memory check counts what a run holds (issue 14, item 4): the lag matrices and triplets, and
per rank the element cache (bounded by the blocks of its rows), one chunk of triplets and the
process as it stands (measured), with no fixed per-rank constant; the memory available is the
machine's or its cgroup's limit, whichever is lower; a mesh that cannot fit is refused from a
sample of rows, before the full count."""
import json
import time

from helpers import cli
import pytest

pytestmark = pytest.mark.mpi


def test_cgroup_limits_are_read(tmp_path):
    from petsc_ssi.sysmem import _cgroup_limit
    v2 = tmp_path / "v2"
    (v2 / "job").mkdir(parents=True)
    (v2 / "job" / "memory.max").write_text("8589934592\n")
    (tmp_path / "cg2").write_text("0::/job\n")
    assert _cgroup_limit(str(tmp_path / "cg2"), str(v2)) == 8589934592.0
    (v2 / "job" / "memory.max").write_text("max\n")
    assert _cgroup_limit(str(tmp_path / "cg2"), str(v2)) == float("inf")
    v1 = tmp_path / "v1"
    (v1 / "memory" / "slurm").mkdir(parents=True)
    (v1 / "memory" / "slurm" / "memory.limit_in_bytes").write_text("4294967296\n")
    (tmp_path / "cg1").write_text("12:cpu,cpuacct:/slurm\n11:memory:/slurm\n")
    assert _cgroup_limit(str(tmp_path / "cg1"), str(v1)) == 4294967296.0
    (v1 / "memory" / "slurm" / "memory.limit_in_bytes").write_text("9223372036854771712\n")   # v1: no limit
    assert _cgroup_limit(str(tmp_path / "cg1"), str(v1)) == float("inf")


def test_the_estimate_bounds_the_measured_peak(tmp_path):
    """runs/pekeris/small.opts (the quarter model): the estimated assembly peak is
    above the measured peak resident memory of the ranks (summed) and within 3x of it, on 1 and 2
    ranks; the issue's case, -ssi_memory_limit 4 on 2 ranks, runs (it was refused at 4.2 GB)."""
    for n in (1, 2):
        out = str(tmp_path / f"s{n}.h5")
        cli(["-options_file", "runs/pekeris/small.opts", "-ssi_output", out, "-ssi_memory_limit", "4"], nranks=n)
        st = json.load(open(out.replace(".h5", ".json")))["stats"]
        est, meas = st["mem_peak_estimate"], st["peak_rss_sum_bytes"]
        assert meas < est < 3.0 * meas, (n, est / 1e9, meas / 1e9)


def test_a_mesh_that_cannot_fit_is_refused_fast(tmp_path, monkeypatch):
    """A 160 m x 160 m surface with 1 m elements and 251 lags (about 58 TB of block-sparse lags)
    is refused from a sample of rows in one line on 2 ranks, well within a minute (the full count
    took 118 s before the sample existed)."""
    monkeypatch.setenv("PETSC_SSI_TEST_MPI_WAIT", "0")    # (the suite's mpirun: no wait for other workers' mpiruns in
    t0 = time.perf_counter()                               # the time measured here; tests/bin/mpirun)
    r = cli(["-ssi_problem", "bem", "-ssi_mesh_size", "160,160", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
             "-ssi_load_group", "load", "-ssi_load_p0", "1", "-ssi_dt", "0.002", "-ssi_t_end", "0.5",
             "-ssi_warn_beta", "0", "-ssi_output", str(tmp_path / "x.h5")], nranks=2, check=False)
    wall = time.perf_counter() - t0
    errs = [ln for ln in r.stderr.splitlines() if ln.startswith("petsc-ssi: error: ")]
    assert r.returncode == 2 and len(errs) == 1 and "estimated from a sample of rows" in errs[0], r.stdout[-1500:]
    assert wall < 60, wall
