"""A long run's output stays sized by its data (issue 28): each flush replaces the series and HDF5 does
not reuse the space of deleted datasets, so the file grew with the number of flushes (the 30 s record
of jobscripts/long_record.sh: 262 MB for 29 MB of data). The final close copies such a file compactly
(io/output.py compactable + rewrite_without_times): here 20 replacements of a 1 MB series leave a file
of about 11 MB, which the copy brings back to the data's size, every value and attribute kept."""
import os

import h5py
import numpy as np

from petsc_ssi.io.output import compactable, rewrite_without_times


def test_a_file_grown_by_flushes_is_compacted(tmp_path):
    p = str(tmp_path / "out.h5")
    rng = np.random.default_rng(1)
    with h5py.File(p, "w") as f:
        f.attrs["run_status"] = "completed"
        f.create_dataset("topology", data=np.arange(12).reshape(3, 4))
    for k in range(20):                           # what 20 flushes of a growing series do: each opens
        with h5py.File(p, "a") as f:              # the file, replaces the series and closes it
            if "receivers" in f:
                del f["receivers"]
            g = f.create_group("receivers")
            d = g.create_dataset("u", data=rng.standard_normal((k + 1) * 6250))   # up to 1 MB
            d.attrs["unit"] = "m"
            last = f["receivers/u"][()]
            f.create_dataset(f"displacement_{k:06d}", data=np.full(1000, float(k)))   # a snapshot after it
    assert os.path.getsize(p) > 10e6 and compactable(p, margin=1e6)
    rewrite_without_times(p)
    assert os.path.getsize(p) < 1.5e6 and not compactable(p, margin=1e6)
    with h5py.File(p, "r") as f:
        assert np.array_equal(f["receivers/u"][()], last) and f["receivers/u"].attrs["unit"] == "m"
        assert f.attrs["run_status"] == "completed" and f["topology"].shape == (3, 4)


def test_virtual_datasets_are_left_alone(tmp_path):
    """A file with a virtual dataset (the member forces' series) is not copied: the copy would store
    the data twice."""
    p = str(tmp_path / "v.h5")
    with h5py.File(p, "w") as f:
        f.create_dataset("a", data=np.zeros(10))
        lay = h5py.VirtualLayout(shape=(10,), dtype="f8")
        lay[:] = h5py.VirtualSource(f["a"])
        f.create_virtual_dataset("v", lay)
    for k in range(10):
        with h5py.File(p, "a") as f:
            f.create_dataset(f"junk{k}", data=np.zeros(200000))
            f.create_dataset(f"keep{k}", data=np.zeros(10))
        with h5py.File(p, "a") as f:
            del f[f"junk{k}"]
    assert os.path.getsize(p) > 10e6
    assert not compactable(p, margin=1e6)
