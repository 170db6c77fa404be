#!/usr/bin/env bash
# Benchmark of the coupled foundation example (issue 5): the six cases of
# runs/foundation (symmetric/antisymmetric load, bonded/unilateral interface, and the
# antisymmetric unilateral case with cohesive open nodes, and the staggered step) at
# 1 and 2 ranks with -log_view -memory_view; then the table in
# runs/foundation/README.md (jobscripts/foundation_table.py) and the figures
# (runs/foundation/figures.py) from the logs and HDF5 outputs.
#   bash jobscripts/foundation_bench.sh [CASES...]   (default: all six)
# On a cluster, put the mpirun line in a job script (jobscripts/slurm.sbatch).
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
RANKS=${RANKS:-"1 2"}
CASES=${*:-"sym-bonded sym-unilateral anti-bonded anti-unilateral anti-unilateral-cohesive sym-bonded-staggered"}
OUT=out/bench
mkdir -p "$OUT"
for case in $CASES; do
  for n in $RANKS; do
    log="$OUT/foundation-$case-n$n.log"
    echo "[bench] $case on $n rank(s) -> $log"
    mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi \
      -options_file "runs/foundation/$case.opts" -ssi_output "$OUT/foundation-$case-n$n.h5" -ssi_output_overwrite \
      -log_view -memory_view > "$log" 2>&1
  done
done
"$PY" jobscripts/foundation_table.py "$OUT" runs/foundation/README.md runs/foundation/bench.csv
"$PY" runs/foundation/figures.py "$OUT" runs/foundation
