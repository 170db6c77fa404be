"""The output's parts (issue 30: a SIGKILL inside HDF5's in-place metadata updates tore the file, 1 in
400 kills of jobscripts/kill_flush_stress.py at 2 ranks): the viewer's datasets go into parts that are
never written again once a flush closed them, FILE.h5 is written anew and renamed at each flush, and
the final close puts everything into FILE.h5 (io/output.py Output). Checked here in-process (one
rank) through Output itself: the closed parts' bytes do not change at later flushes, every flush's
FILE.h5 reads whole, the parts are merged so a long run keeps few files, the final file holds every
dataset itself (no links, no parts directory) and is the same bytes for the same data, and a restart
continues a file whose datasets are its own or in parts."""
import hashlib
import os

import h5py
import numpy as np
import pytest

from petsc_ssi.io import output as output_mod
from petsc_ssi.io.output import Output, parts_dir
from petsc_ssi.petsc import init, SSIError

pytestmark = pytest.mark.run

PETSc = init()
N = 50


def _vec(value):
    v = PETSc.Vec().createMPI(3 * N, bsize=3, comm=PETSc.COMM_WORLD)
    v.set(value)
    return v


def _digest(path):
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def _series(k):
    t = 0.01 * np.arange(1, k + 1)
    return {"points": np.zeros((2, 3)), "t": t, "u": np.repeat(t[:, None, None], 6, axis=1).reshape(k, 2, 3)}


def _check(path, k, n_snap):
    """FILE.h5 as the flush of step k left it: the series, every snapshot with its value and unit."""
    with h5py.File(path, "r") as f:
        assert f.attrs["n_snapshots"] == n_snap and len(f["time"]) == n_snap
        assert np.array_equal(f["receivers/t"][:], 0.01 * np.arange(1, k + 1))
        assert f["coordinates"].shape == (N, 3) and f["coordinates"].attrs["unit"] == "m"
        for j in range(n_snap):
            d = f[f"displacement_{j:06d}"]
            assert np.all(d[:] == j + 1) and d.attrs["unit"] == "m", j


def _run(path, flushes, final=True, resume=None, start=0):
    """Output at ``path``: a snapshot and a flush per step (steps start+1 .. start+flushes); returns the
    Output and the parts' digests taken when each was first named by FILE.h5."""
    out = Output(path, PETSc.COMM_WORLD, resume=resume)
    x = _vec(0.0)
    out.write_mesh(x, np.zeros((N // 4, 4), np.int64), "quad4")
    seen = {}
    for k in range(start + 1, start + flushes + 1):
        out.write_fields(0.01 * k, {"displacement": _vec(float(k))})
        out.flush(receivers=_series(k), attrs={"steps_done": k})
        _check(path, k, k)
        with h5py.File(path, "r") as f:
            for name in f:
                ln = f.get(name, getlink=True)
                if isinstance(ln, h5py.ExternalLink):
                    part = os.path.join(os.path.dirname(path), ln.filename)
                    seen.setdefault(part, _digest(part))
        for part, digest in seen.items():                 # a part FILE.h5 names is never written again
            if os.path.exists(part):
                assert _digest(part) == digest, part
    if final:
        out.close(receivers=_series(start + flushes), attrs={"steps_done": start + flushes})
    return out, seen


def test_flushed_parts_are_never_written_again_and_merge(tmp_path):
    p = str(tmp_path / "o.h5")
    n = 2 * output_mod.MERGE_EVERY + 3
    out, seen = _run(p, n, final=False)
    assert sum("/m1-" in s for s in seen) == 2 and len(seen) == n   # the parts, less the two merged
    # in the flush that closed them, and the two merged ones
    files = os.listdir(parts_dir(p))
    assert len(files) <= output_mod.MERGE_EVERY + 2, files    # merged: 2 level-1 parts and 3 new ones
    assert sum(f.startswith("m1-") for f in files) == 2
    out.close(receivers=_series(n), attrs={"steps_done": n})
    assert not os.path.exists(parts_dir(p))
    _check(p, n, n)
    with h5py.File(p, "r") as f:
        assert not any(isinstance(f.get(name, getlink=True), h5py.ExternalLink) for name in f)
        assert f.attrs["run_status"] == "completed"


def test_the_file_is_sized_by_its_data(tmp_path):
    """Each flush writes FILE.h5 anew: a long run's flushes of a growing series do not pile up in it
    (before the parts, 20 replacements of a 1 MB series left an 11 MB file until the final copy)."""
    p = str(tmp_path / "s.h5")
    out = Output(p, PETSc.COMM_WORLD)
    out.write_mesh(_vec(0.0), np.zeros((N // 4, 4), np.int64), "quad4")
    rng = np.random.default_rng(1)
    for k in range(20):
        big = {"big": (rng.standard_normal((k + 1) * 6250), "m")}
        out.flush(groups={"series": big})
        assert os.path.getsize(p) < 1.2 * 8 * (k + 1) * 6250 + 0.1e6
    out.close(groups={"series": big})
    assert os.path.getsize(p) < 1.3e6
    with h5py.File(p, "r") as f:
        assert np.array_equal(f["series/big"][()], big["big"][0]) and f["series/big"].attrs["unit"] == "m"


def test_the_final_file_is_the_same_bytes_for_the_same_data(tmp_path):
    a, b = str(tmp_path / "a.h5"), str(tmp_path / "b.h5")
    _run(a, 5)
    _run(b, 5)
    assert _digest(a) == _digest(b)


@pytest.mark.parametrize("finished", [True, False], ids=["finished file", "file with parts"])
def test_a_restart_continues_the_file(tmp_path, finished):
    """The interrupted run's file (merged by a final close, or still linking its parts) continued from
    its 4th snapshot: the new snapshots replace those after it, every dataset reads right."""
    p = str(tmp_path / "r.h5")
    _run(p, 6, final=finished)
    resume = {"times": 0.01 * np.arange(1, 5), "fields": "displacement"}
    out, _ = _run(p, 5, resume=resume, start=4)
    _check(p, 9, 9)
    assert not os.path.exists(parts_dir(p))


def test_a_leftover_parts_directory_is_refused(tmp_path):
    p = str(tmp_path / "l.h5")
    os.makedirs(parts_dir(p))
    with pytest.raises(SSIError, match=r"l\.parts exists \(the parts of an earlier run\)"):
        output_mod.check_output(p, PETSc.COMM_WORLD)
    output_mod.check_output(p, PETSc.COMM_WORLD, overwrite=True)


def test_paraview_reads_a_running_file(tmp_path):
    """ParaView's XDMF reader does not follow HDF5's external links (it reported "Can't Open Dataset
    FILE.h5:/coordinates" and crashed): while the run goes on the .xmf names each dataset's part. Every
    snapshot reads right from the flushed, unfinished output (skipped without pvpython)."""
    from helpers import pv_or_skip, pvpython
    pv_or_skip()
    p = str(tmp_path / "run.h5")
    _run(p, 3, final=False)
    got = pvpython("r.UpdatePipelineInformation()\nout = []\n"
                   "for t in r.TimestepValues:\n    r.UpdatePipeline(t)\n"
                   "    d = dsa.WrapDataObject(sm.Fetch(r))\n"
                   "    out.append([t, int(d.GetNumberOfPoints()), np.asarray(d.PointData['displacement']).tolist()])\n"
                   "print(json.dumps(out))\n", p.replace(".h5", ".xmf"), tmp_path)
    assert [g[0] for g in got] == pytest.approx([0.01, 0.02, 0.03])
    for j, (t, npts, u) in enumerate(got):
        assert npts == N and np.all(np.array(u) == j + 1), j


def test_a_restart_without_the_parts_is_refused(tmp_path):
    """A running file moved without its parts directory: the restart says so in one line before
    writing anything."""
    import shutil
    p = str(tmp_path / "m.h5")
    _run(p, 3, final=False)
    shutil.rmtree(parts_dir(p))
    with pytest.raises(SSIError, match=r"m\.h5 links its dataset coordinates to m\.parts/p000000\.h5, which is missing"):
        Output(p, PETSc.COMM_WORLD, resume={"times": [0.01], "fields": "displacement"})


def test_no_room_for_the_final_copy_keeps_the_links(tmp_path, monkeypatch, capsys):
    """A disk without room to copy the parts into FILE.h5 at the end: a warning, and FILE.h5 stays
    whole, linked to its parts, with the final status."""
    import shutil
    from collections import namedtuple
    p = str(tmp_path / "f.h5")
    out, _ = _run(p, 3, final=False)
    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda d: usage(1e9, 1e9, 1000.0))
    out.close(receivers=_series(3), attrs={"steps_done": 3})
    assert "too little to copy its parts" in capsys.readouterr().out
    _check(p, 3, 3)
    with h5py.File(p, "r") as f:
        assert f.attrs["run_status"] == "completed"
        assert isinstance(f.get("displacement_000000", getlink=True), h5py.ExternalLink)


def test_member_forces_virtual_datasets_carry_no_time(tmp_path):
    """The member forces' series is a virtual dataset; h5py's create_virtual_dataset records its
    creation time, so two runs' identical results gave files of other bytes (a second apart). The
    forces' writer creates it without one (fem/forces.py _virtual)."""
    import time
    from petsc_ssi.fem.forces import _virtual
    from petsc_ssi.io.output import _new_file
    digests = []
    for k in range(2):
        p = str(tmp_path / f"v{k}.h5")
        with _new_file(p) as f:
            f.create_dataset("a", data=np.arange(6.0).reshape(2, 3), track_times=False)
            lay = h5py.VirtualLayout(shape=(1, 2, 3), dtype="f8")
            lay[0] = h5py.VirtualSource(".", "a", shape=(2, 3))
            _virtual(f, "v", lay, np.nan)
        with h5py.File(p, "r") as f:
            assert np.array_equal(f["v"][0], np.arange(6.0).reshape(2, 3))
        digests.append(_digest(p))
        time.sleep(1.1)
    assert digests[0] == digests[1]


def test_a_restart_drops_the_snapshots_after_its_checkpoint(tmp_path):
    """Snapshots the interrupted run wrote after its checkpoint are not adopted: a restart that
    writes fewer than those leaves none of them in the file."""
    p = str(tmp_path / "d.h5")
    _run(p, 6, final=False)
    resume = {"times": 0.01 * np.arange(1, 3), "fields": "displacement"}
    out, _ = _run(p, 2, resume=resume, start=2)
    _check(p, 4, 4)
    with h5py.File(p, "r") as f:
        assert "displacement_000004" not in f and "displacement_000005" not in f


def test_output_merge_off_keeps_the_links(tmp_path):
    """-ssi_output_merge 0: the final close writes FILE.h5 with the final status and links to its
    parts, copying nothing (for outputs too large to copy once more at the end)."""
    p = str(tmp_path / "k.h5")
    opts = PETSc.Options()
    opts["ssi_output_merge"] = "0"
    try:
        _run(p, 3)
    finally:
        opts.delValue("ssi_output_merge")
    _check(p, 3, 3)
    with h5py.File(p, "r") as f:
        assert f.attrs["run_status"] == "completed"
        assert isinstance(f.get("displacement_000002", getlink=True), h5py.ExternalLink)
    assert os.path.isdir(parts_dir(p))
