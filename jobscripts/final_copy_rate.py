"""What the output's final copy costs (issue 30, io/output.py: the final close copies the datasets of
FILE.parts/ into FILE.h5 on rank 0, in slabs): GB of snapshot-like datasets (N x 3 float64, 8 MB each)
written to a part, then copied as the final close does (`_copy_dataset` into a file without
modification times), both followed by sync; prints the copy's rate. -ssi_output_merge 0 skips the
copy (FILE.h5 then keeps linking its parts).

    python jobscripts/final_copy_rate.py [GB] [DIR]        (default 1 GB in out/copy_rate)
"""
import os
import sys
import time

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from petsc_ssi.io.output import _copy_dataset, _new_file  # noqa: E402


def main(gb=1.0, where=None):
    where = where or os.path.join(ROOT, "out", "copy_rate")
    os.makedirs(where, exist_ok=True)
    src, dst = os.path.join(where, "part.h5"), os.path.join(where, "final.h5")
    rows = 8_000_000 // 24
    n = max(1, int(gb * 1e9 / (24 * rows)))
    with h5py.File(src, "w") as f:
        for k in range(n):
            f[f"displacement_{k:06d}"] = np.random.default_rng(k).standard_normal((rows, 3))
    os.sync()
    size = os.path.getsize(src)
    t = time.perf_counter()
    with _new_file(dst) as d, h5py.File(src, "r") as s:
        for name in s:
            _copy_dataset(s[name], d, name)
    os.sync()
    dt = time.perf_counter() - t
    print(f"final copy: {size / 1e9:.2f} GB in {n} datasets copied in {dt:.2f} s: {size / 1e9 / dt:.2f} GB/s "
          f"(sync included; {where})")
    for f in (src, dst):
        os.remove(f)


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 1.0, sys.argv[2] if len(sys.argv) > 2 else None)
