#!/usr/bin/env bash
# The small Lamb case (runs/pekeris/small.opts) at 1 rank and at each of RANKS (default "3 4"; more
# ranks than cores are oversubscribed), and the largest difference of every receiver series from the
# 1-rank run relative to its maximum: the shared element cache and the partition at rank counts the
# test suite (1 and 2 ranks) does not run.
#   bash jobscripts/ranks_agree.sh [RANKS]
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
RANKS=${1:-"3 4"}
OUT=out/bench/ranks_agree
mkdir -p "$OUT"
for n in 1 $RANKS; do
  mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi -options_file runs/pekeris/small.opts \
    -ssi_output "$OUT/small-n$n.h5" -ssi_output_overwrite > "$OUT/small-n$n.log" 2>&1
done
"$PY" - "$OUT" $RANKS <<'PY'
import sys
import h5py
import numpy as np
out, ranks = sys.argv[1], sys.argv[2:]
def receivers(path):
    got = {}
    with h5py.File(path, "r") as f:
        f["receivers"].visititems(lambda n, o: got.__setitem__(n, o[()]) if isinstance(o, h5py.Dataset) and o.dtype.kind == "f" else None)
    return got
ref = receivers(f"{out}/small-n1.h5")
for n in ranks:
    other = receivers(f"{out}/small-n{n}.h5")
    d = max(float(np.abs(ref[k] - other[k]).max() / max(float(np.abs(ref[k]).max()), 1e-300)) for k in ref)
    print(f"{n} ranks against 1 rank: {len(ref)} receiver series, largest relative difference {d:.2g}")
PY
