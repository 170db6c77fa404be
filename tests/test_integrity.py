"""Lost or unreadable results and corrupt files (issue 30).

Every bad case runs at -n 1 and -n 2 (the harness of tests/test_output_safety.py) and must end with
ONE line 'petsc-ssi: error: ...', exit status 2 on every rank, no traceback, no time step taken,
and every file that existed before untouched:

  * a lag file (-ssi_lags_load) or a checkpoint (-ssi_restart) with damaged bytes inside a
    matrix's or a dataset's data is refused by the CRC32 of its content (io/integrity.py), naming
    the file (before: the run used it);
  * a restart into an existing -ssi_output of another run (the run id of the output and of the
    checkpoint differ) is refused (before: the restart appended into it);
  * a checkpoint or lag file named like an output or a sidecar of the run is refused (before: it
    replaced the output);
  * a second run on files another live run holds (OUT.h5.lock, ck-%d.h5.lock) is refused; a
    stale lock (its pid gone) is taken over with a warning; the lock is gone after the run.

The case: the 4 x 4 m Pekeris patch of test_output_safety, 6 steps (about a second a run)."""
import os
import platform
import shutil
import subprocess
import sys

import h5py
import numpy as np

from helpers import cli
import pytest

pytestmark = pytest.mark.mpi

SMALL = ["-ssi_problem", "bem", "-ssi_mesh_size", "4,4", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
         "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.005", "-ssi_t_end", "0.03",
         "-ssi_output_stride", "2", "-ssi_receivers", "2,0,0", "-ssi_warn_beta", "0"]


def refused(r):
    """The one error line of a refused run (exit 2, no traceback, no step taken)."""
    lines = [ln for ln in r.stderr.splitlines() if ln.startswith("petsc-ssi: error: ")]
    assert r.returncode == 2, r.stdout[-2000:] + r.stderr[-2000:]
    assert len(lines) == 1, r.stdout[-2000:]
    assert "Traceback" not in r.stderr, r.stderr[-2000:]
    assert "done in" not in r.stdout and "step 1/" not in r.stdout, r.stdout[-2000:]
    return lines[0]


def files(d):
    """{name: bytes} of every file in d."""
    return {f: open(os.path.join(d, f), "rb").read() for f in sorted(os.listdir(d))
            if os.path.isfile(os.path.join(d, f))}


def flip(path, offset, nbytes=1):
    """Damage ``nbytes`` bytes at ``offset`` (XOR 0x10: the data stay finite doubles)."""
    with open(path, "r+b") as fh:
        fh.seek(offset)
        b = bytearray(fh.read(nbytes))
        fh.seek(offset)
        fh.write(bytes(x ^ 0x10 for x in b))


def data_offset(path, name):
    """The file offset of dataset ``name``'s data (contiguous, or its first chunk)."""
    with h5py.File(path, "r") as f:
        ds = f[name]
        off = ds.id.get_offset()
        return off if off is not None else ds.id.get_chunk_info(0).byte_offset


def test_a_damaged_lag_file_is_refused(tmp_path):
    """Bytes flipped inside the last matrix's values (the end of the PETSc binary file): refused
    at -n 1 and -n 2 naming the file; the intact copy loads and gives the saving run's receivers
    bitwise (one rank)."""
    lags = str(tmp_path / "soil.lags")
    a = str(tmp_path / "a.h5")
    cli(SMALL + ["-ssi_output", a, "-ssi_lags_save", lags])
    assert os.path.exists(lags + ".json")
    bad = str(tmp_path / "bad.lags")
    shutil.copy(lags, bad)
    shutil.copy(lags + ".json", bad + ".json")
    flip(bad, os.path.getsize(bad) - 4)                 # inside the last stored double
    for n in (1, 2):
        err = refused(cli(SMALL + ["-ssi_output", str(tmp_path / f"x{n}.h5"), "-ssi_lags_load", bad], nranks=n,
                          check=False))
        assert f"-ssi_lags_load {bad}: the content differs from the checksum saved with it" in err, err
        assert not os.path.exists(tmp_path / f"x{n}.h5")
    b = str(tmp_path / "b.h5")
    cli(SMALL + ["-ssi_output", b, "-ssi_lags_load", lags])
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        assert np.array_equal(fa["receivers/u"][()], fb["receivers/u"][()]) and np.abs(fa["receivers/u"][()]).max() > 0


def test_a_damaged_checkpoint_is_refused(tmp_path):
    """Bytes flipped inside a Vec of the soil's history (PETSc's chunked dataset) or inside a
    serial series (h5py's contiguous one, at -n 2): refused at -n 1 and -n 2 naming the checkpoint
    and the dataset, the output of the interrupted run untouched. (Intact checkpoints restart:
    tests/test_checkpoint.py.)"""
    run = tmp_path / "run"
    run.mkdir()
    out = str(run / "r.h5")
    cli(SMALL + ["-ssi_output", out, "-ssi_checkpoint", str(tmp_path / "ck-%d.h5"), "-ssi_checkpoint_every", "2"])
    ck = str(tmp_path / "ck-4.h5")
    with h5py.File(ck, "r") as f:
        vec = sorted(k for k in f if k.startswith("bem_u_"))[-1]
        assert f[vec].chunks is not None
    for name, ranks in ((vec, (1, 2)), ("serial/times", (2,))):
        bad = str(tmp_path / "bad.h5")
        shutil.copy(ck, bad)
        flip(bad, data_offset(bad, name) + 13)
        before = files(run)
        for n in ranks:
            err = refused(cli(SMALL + ["-ssi_output", out, "-ssi_restart", bad], nranks=n, check=False))
            assert f"-ssi_restart {bad}: the data of {name} differ from their checksum" in err, err
            assert files(run) == before
    with h5py.File(ck, "r") as f:
        assert len(f[vec].attrs["crc32"]) == 1 and len(f["serial/times"].attrs["crc32"]) == 1   # one 8 MiB piece


# slow tier: the make-test budget (10-20 s); the default tier's sibling: test_a_damaged_checkpoint_is_refused
@pytest.mark.slow
def test_a_restart_does_not_continue_another_runs_output(tmp_path):
    """-ssi_restart of run A with -ssi_output naming run B's finished result (another run id) is
    refused at -n 1 and -n 2, B untouched; A's own output (a copy keeps its id) restarts."""
    a, b = str(tmp_path / "a.h5"), str(tmp_path / "b.h5")
    cli(SMALL + ["-ssi_output", a, "-ssi_checkpoint_every", "2"])
    cli(SMALL + ["-ssi_output", b, "-ssi_load_p0", "2000"])
    keep = open(b, "rb").read()
    for n in (1, 2):
        err = refused(cli(SMALL + ["-ssi_output", b, "-ssi_restart", str(tmp_path / "a-checkpoint.h5")], nranks=n,
                          check=False))
        assert f"-ssi_output {b}: exists and is not the output of the run that wrote -ssi_restart" in err, err
        assert open(b, "rb").read() == keep
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb, h5py.File(str(tmp_path / "a-checkpoint.h5"), "r") as fc:
        ida, idb = str(fa.attrs["run_id"]), str(fb.attrs["run_id"])
        assert len(ida) == 32 and ida != idb and str(fc.attrs["run_id"]) == ida
    c = str(tmp_path / "c.h5")
    shutil.copy(a, c)
    cli(SMALL + ["-ssi_output", c, "-ssi_restart", str(tmp_path / "a-checkpoint.h5")], nranks=2)
    with h5py.File(c, "r") as fc:
        assert str(fc.attrs["run_id"]) == ida and str(fc.attrs["run_status"]) == "completed"


# slow tier: checkpoint and lag names against every output and sidecar (20 s; the locks' tests stay)
@pytest.mark.slow
def test_checkpoint_and_lag_files_may_not_be_outputs(tmp_path):
    """A checkpoint or lag file named like the output, a sidecar of it, or each other: refused at
    -n 1 and -n 2 even with -ssi_output_overwrite, before any step; the earlier result untouched."""
    out = str(tmp_path / "o.h5")
    cli(SMALL + ["-ssi_output", out])
    ow = ["-ssi_output", out, "-ssi_output_overwrite"]
    cases = [
        (["-ssi_checkpoint", out, "-ssi_checkpoint_every", "2"], f"-ssi_checkpoint {out}: would replace {out}, "
                                                                 "the output"),
        (["-ssi_checkpoint", str(tmp_path / "o.json")], "sidecar"),
        (["-ssi_output", str(tmp_path / "o-4.h5"), "-ssi_checkpoint", str(tmp_path / "o-%d.h5"),
          "-ssi_checkpoint_every", "2"], "o-4.h5, the output"),
        (["-ssi_lags_save", out], f"-ssi_lags_save {out}: would replace {out}, the output"),
        (["-ssi_lags_save", str(tmp_path / "o-checkpoint.h5")], "a checkpoint needs a name of its own"),
        (["-ssi_lags_save", str(tmp_path / "l.h5"), "-ssi_checkpoint", str(tmp_path / "l.h5.tmp")],
         "-ssi_lags_save's"),
    ]
    before = files(tmp_path)
    for i, (extra, msg) in enumerate(cases):
        for n in ((1, 2) if i < 2 else (2,)):              # (every case at -n 2; -n 1 for two: cheap)
            err = refused(cli(SMALL + ow + extra, nranks=n, check=False))
            assert msg in err, (extra, err)
            assert files(tmp_path) == before, extra


def _lock(path, pid, host=None):
    with open(path + ".lock", "w") as fh:
        fh.write(f"host {host or platform.node()}\npid {pid}\nstarted 2026-01-01T00:00:00\n")


def test_a_file_another_live_run_writes_is_refused(tmp_path):
    """OUT.h5.lock of a live process on this host (the test's own pid), or of another host, and
    the lock of a checkpoint pattern (ck-%d.h5.lock): the second run is refused (the first case at
    -n 1 and -n 2, the others at -n 1) naming the lock, no file written. A stale lock (a finished process's pid) is taken over with a
    warning; a finished run leaves no lock."""
    out = str(tmp_path / "o.h5")
    ck = str(tmp_path / "ck-%d.h5")
    for target, host, extra, ranks in ((out, None, [], (1, 2)), (out, "elsewhere.example", [], (1,)),
                                       (ck, None, ["-ssi_checkpoint", ck, "-ssi_checkpoint_every", "2"], (1,))):
        _lock(target, os.getpid(), host)
        for n in ranks:
            err = refused(cli(SMALL + ["-ssi_output", out] + extra, nranks=n, check=False))
            assert f"{target} is being written by another run" in err and f"pid {os.getpid()}" in err, err
            assert sorted(os.listdir(tmp_path)) == [os.path.basename(target) + ".lock"]
        os.remove(target + ".lock")
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    _lock(out, int(gone.stdout))
    r = cli(SMALL + ["-ssi_output", out] + ["-ssi_checkpoint", ck, "-ssi_checkpoint_every", "2"], nranks=2)
    assert f"took over the stale lock {out}.lock of pid {int(gone.stdout)}" in r.stdout, r.stdout[-2000:]
    assert not any(f.endswith(".lock") for f in os.listdir(tmp_path)), os.listdir(tmp_path)
    with h5py.File(out, "r") as f:
        assert str(f.attrs["run_status"]) == "completed"


def test_two_runs_started_at_once_leave_a_readable_output(tmp_path):
    """Two runs with the same -ssi_output (and -ssi_output_overwrite) started together: the second
    to arrive is refused by the lock while the first runs (or, arriving after it, replaces the
    finished file): no crash, and the file is a complete, readable result."""
    out = str(tmp_path / "o.h5")
    cmd = [sys.executable, "-m", "petsc_ssi"] + SMALL + ["-ssi_t_end", "0.1", "-ssi_output", out,
                                                         "-ssi_output_overwrite"]
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    ps = [subprocess.Popen(cmd, cwd=root, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
          for _ in range(2)]
    res = [p.communicate(timeout=300) for p in ps]
    codes = [p.returncode for p in ps]
    assert sorted(codes) in ([0, 0], [0, 2]), (codes, res)
    for (so, se), c in zip(res, codes):
        assert "Traceback" not in se, se[-2000:]
        if c == 2:
            assert f"{out} is being written by another run" in se, se[-2000:]
    with h5py.File(out, "r") as f:
        assert str(f.attrs["run_status"]) == "completed" and f["receivers/u"].shape[0] == 20   # 0.1 s / 5 ms
    assert not os.path.exists(out + ".lock")
