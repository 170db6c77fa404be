#!/usr/bin/env bash
# Strong scaling: one case (options file) at several rank counts.
#   bash jobscripts/strong_scaling.sh OPTIONS_FILE [RANKS...]     (default ranks: 1 2 4)
# Writes OUT/strong-<case>-n<ranks>.log (-log_view -memory_view), then the CSV,
# plots and the table of jobscripts/README.md (jobscripts/scaling.py). The same
# script runs in a SLURM/PBS job (jobscripts/slurm.sbatch, jobscripts/pbs.sh);
# environment: see jobscripts/scaling_common.sh.
source "$(dirname "$0")/scaling_common.sh"
OPTS=${1:?usage: strong_scaling.sh OPTIONS_FILE [RANKS...]}
shift
RANKS=${*:-"1 2 4"}
case=$(basename "$OPTS" .opts)
for n in $RANKS; do
  run_case "$OUT/strong-$case-n$n.log" "$n" strong "$case" \
    -options_file "$OPTS" -ssi_output "$OUT/strong-$case-n$n.h5" -ssi_output_stride 0
done
[ "${NO_REPORT:-0}" = 1 ] || "$PY" jobscripts/scaling.py "$OUT"
