#!/usr/bin/env bash
# The element cache shared between ranks (-ssi_cache_share 1, default) against per-rank caches (0):
# the medium Pekeris case on RANKS ranks, REPS alternating runs of each, plus one 1-rank reference.
# Writes out/cache_share/*.log and jobscripts/results/cache_share.csv (SSI_BEM_Assembly seconds from
# -log_view, kernel evaluations summed over the ranks, max relative difference of the receiver
# histories from the 1-rank run).
#   LOCK="flock /tmp/ssi_cpu.lock" bash jobscripts/cache_share_bench.sh
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
RANKS=${RANKS:-"2 4"}
REPS=${REPS:-3}
OPTS=${OPTS:-runs/pekeris/medium.opts}
OUT=out/cache_share
mkdir -p "$OUT"
run() {  # ranks share rep
  local log="$OUT/n$1-share$2-rep$3.log"
  echo "[cache_share] $1 rank(s), -ssi_cache_share $2, run $3 -> $log"
  ${LOCK:-} mpirun --allow-run-as-root --oversubscribe -n "$1" "$PY" -m petsc_ssi -options_file "$OPTS" \
    -ssi_output "$OUT/n$1-share$2-rep$3.h5" -ssi_output_overwrite -ssi_output_stride 0 -ssi_cache_share "$2" -log_view > "$log" 2>&1
}
# warm-up (not recorded): numba compiles the kernels into its cache on first use
${LOCK:-} mpirun --allow-run-as-root --oversubscribe -n 2 "$PY" -m petsc_ssi -options_file runs/pekeris/small.opts \
  -ssi_output "$OUT/warmup.h5" -ssi_output_overwrite -ssi_output_stride 0 > "$OUT/warmup.log" 2>&1
run 1 1 1
for n in $RANKS; do
  for rep in $(seq 1 "$REPS"); do run "$n" 0 "$rep"; run "$n" 1 "$rep"; done
done
"$PY" - "$OUT" <<'PY'
import csv, glob, os, re, sys
import h5py
import numpy as np
out = sys.argv[1]
ref = h5py.File(os.path.join(out, "n1-share1-rep1.h5"))["receivers/u"][:]
rows = []
for log in sorted(glob.glob(os.path.join(out, "n*-share*-rep*.log"))):
    n, share, rep = map(int, re.search(r"n(\d+)-share(\d)-rep(\d+)", log).groups())
    text = open(log).read()
    asm = float(re.search(r"^SSI_BEM_Assembly\s+\d+\s+[\d.]+\s+([\d.e+-]+)", text, re.M).group(1))
    nev = float(re.search(r"([0-9.e+]+) kernel evaluations", text).group(1))
    u = h5py.File(log[:-4] + ".h5")["receivers/u"][:]
    diff = float(np.abs(u - ref).max() / np.abs(ref).max())
    rows.append({"ranks": n, "cache_share": share, "run": rep, "assembly_s": asm, "kernel_evaluations": nev,
                 "rel_diff_vs_1rank": diff})
path = "jobscripts/results/cache_share.csv"
with open(path, "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
for r in rows:
    print(r)
print(f"[cache_share] wrote {path}")
PY
