"""Compare the HDF5 outputs of two runs of jobscripts/refactor_cases.sh bit for bit.

    python jobscripts/compare_outputs.py DIR_A DIR_B

Every *.h5 file of DIR_A must exist in DIR_B with the same datasets (same shape, dtype and bytes)
and the same attributes, except those that record when, where and how long a run took
(provenance, timings, peak memory, paths). Prints one line per file and exits 1 on a difference.
"""
import glob
import os
import sys

import h5py
import numpy as np

SKIP_ATTRS = ("record", "run_record", "provenance", "created", "wall", "time_s", "versions", "command")
SKIP_WORDS = ("wall", "_s", "rss", "time", "record", "path", "output", "host", "date", "git", "argv",
              "options", "elapsed", "estimate", "version")


def _skip(name):
    low = name.lower()
    return any(w in low for w in SKIP_WORDS)


def compare(fa, fb):
    diffs = []

    def visit(name, obj):
        if name not in fb:
            diffs.append(f"{name}: missing")
            return
        other = fb[name]
        if isinstance(obj, h5py.Dataset):
            if _skip(name.split("/")[-1]) and obj.dtype.kind in "SOU":
                return
            a, b = obj[()], other[()]
            if getattr(a, "shape", ()) != getattr(b, "shape", ()) or getattr(a, "dtype", None) != getattr(b, "dtype", None):
                diffs.append(f"{name}: shape/dtype {getattr(a, 'shape', ())}/{getattr(a, 'dtype', '')} vs "
                             f"{getattr(b, 'shape', ())}/{getattr(b, 'dtype', '')}")
            elif isinstance(a, np.ndarray) and a.dtype.kind in "fiuc":
                if a.tobytes() != b.tobytes():
                    d = np.nanmax(np.abs(a.astype(float) - b.astype(float))) if a.size else 0.0
                    diffs.append(f"{name}: values differ (max |a-b| {d:.3g})")
            elif np.asarray(a).tobytes() != np.asarray(b).tobytes():
                diffs.append(f"{name}: differs")
        for k, v in obj.attrs.items():
            if _skip(k):
                continue
            if k not in other.attrs:
                diffs.append(f"{name}@{k}: missing")
            elif np.asarray(v).tobytes() != np.asarray(other.attrs[k]).tobytes():
                diffs.append(f"{name}@{k}: {v!r} vs {other.attrs[k]!r}")
    fa.visititems(visit)
    return diffs


def main(a, b):
    bad = 0
    files = sorted(glob.glob(os.path.join(a, "**", "*.h5"), recursive=True))
    if not files:
        print(f"no .h5 files in {a}")
        return 1
    for pa in files:
        pb = os.path.join(b, os.path.relpath(pa, a))
        if not os.path.exists(pb):
            print(f"{os.path.relpath(pa, a)}: missing in {b}")
            bad += 1
            continue
        with h5py.File(pa, "r") as fa, h5py.File(pb, "r") as fb:
            d = compare(fa, fb)
        n = sum(1 for _ in _walk(pa))
        print(f"{os.path.relpath(pa, a)}: {n} datasets, " + ("identical" if not d else f"{len(d)} differences"))
        for line in d[:20]:
            print("   ", line)
        bad += bool(d)
    return 1 if bad else 0


def _walk(path):
    with h5py.File(path, "r") as f:
        out = []
        f.visititems(lambda n, o: out.append(n) if isinstance(o, h5py.Dataset) else None)
    return out


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
