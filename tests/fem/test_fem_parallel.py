"""Parallel tier (mpirun -n 2): petsc-ssi modes equals -n 1, and a failure on one rank inside
rank-0-only or local work reaches every rank as the same one-line SSIError instead of a hang."""
import os
import subprocess

import h5py
import numpy as np
import pytest

from fem_helpers import ROOT, PY, run_cli

pytestmark = pytest.mark.mpi

HERE = os.path.dirname(os.path.abspath(__file__))


def modes(tmp_path, n, extra):
    out = tmp_path / f"modes_np{n}.h5"
    r = run_cli(["modes", "-ssi_fem_box_cells", "4,4,2", "-ssi_modes_n", "8", "-ssi_output", str(out)] + extra,
                n=n, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    with h5py.File(out) as f:
        return np.asarray(f.attrs["frequencies_hz"]), r.stdout


@pytest.mark.parametrize("extra", [["-ssi_fem_fixed", "base"], ["-ssi_fem_fixed", "xmin:x,ymin:y,base:z"]],
                         ids=["base", "rollers"])
def test_modes_parallel_equals_serial(tmp_path, extra):
    """petsc-ssi modes under mpirun -n 2 (MUMPS inside SLEPc's shift-and-invert, split over the ranks)
    gives the 8 lowest frequencies of -n 1 to 1e-10 relative (full precision, from the HDF5 attribute)."""
    f1, out1 = modes(tmp_path, 1, extra)
    f2, out2 = modes(tmp_path, 2, extra)
    assert len(f1) == len(f2) == 8 and f1[0] > 1.0
    assert np.abs(f2 - f1).max() <= 1e-10 * f1.max(), (f1, f2)
    assert "warning" not in out1 + out2        # a parallel direct solver was found (no serial-LU fall-back)


def test_failure_on_one_rank_reaches_every_rank(tmp_path):
    """A non-SSIError exception on rank 0 (mesh reader, output directory, serial HDF5/XDMF writing) or on
    rank 1 (local stiffness) is raised on BOTH ranks as the same one-line SSIError; no hang (60 s)."""
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OPENBLAS_NUM_THREADS="1")
    r = subprocess.run(["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "2", PY,
                        os.path.join(HERE, "mpi_failures.py"), str(tmp_path)],
                       cwd=ROOT, env=env, capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stdout + r.stderr
    got = {}
    for rank in (0, 1):
        for line in (tmp_path / f"rank{rank}.txt").read_text().splitlines():
            case, msg = line.split(": ", 1)
            got.setdefault(case, {})[rank] = msg
    expected = {"load_mesh": "SSIError: reading the mesh 'box' failed: ValueError: boom on rank 0",
                "assemble": "SSIError: assembling K and M failed on rank 1: MemoryError: no memory on rank 1",
                "output_dir": "SSIError: cannot create the output directory",
                "output_close": "SSIError: writing "}
    for case, start in expected.items():
        assert set(got.get(case, {})) == {0, 1}, (case, r.stdout)
        assert got[case][0] == got[case][1], (case, got[case])          # the same message on both
        assert got[case][0].startswith(start), (case, got[case][0])
        assert "\n" not in got[case][0]
    assert got["output_close"][0].endswith("OSError: disk full")
