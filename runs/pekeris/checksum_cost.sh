#!/bin/sh
# The cost of the CRC32 checksums of lag files (issue 30): -ssi_lags_save and -ssi_lags_load of
# runs/pekeris/small.opts (a 0.371 GB lag file) with this tree and with the tree before the
# checksums (git revision BEFORE, default 7d75961), at 1 and 2 ranks, REPS times each. Save time:
# the run's "saved ... in" line (it includes the checksums, also printed alone); load time: the
# "loaded ... in" line, plus the check's own line (before any heavy work, with checksums).
# Usage: sh runs/pekeris/checksum_cost.sh [BEFORE] [REPS]     (from the repository root)
set -e
BEFORE=${1:-7d75961}
REPS=${2:-3}
PY=${PY:-.venv/bin/python}
[ -x "$PY" ] || { echo "checksum_cost.sh: no $PY (run make deps, or set PY)"; exit 1; }
HERE=$(pwd)
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
mkdir "$TMP/before"
git archive "$BEFORE" | tar -x -C "$TMP/before"
for n in 1 2; do
  for tree in "$HERE" "$TMP/before"; do
    tag=$( [ "$tree" = "$HERE" ] && echo with || echo without )
    for r in $(seq "$REPS"); do
      rm -f "$TMP"/o.* "$TMP"/l.lags*
      sout=$(cd "$tree" && PYTHONPATH="$tree" mpirun --allow-run-as-root --oversubscribe -n $n "$PY" -m petsc_ssi \
             -options_file runs/pekeris/small.opts -ssi_output "$TMP/o.h5" -ssi_lags_save "$TMP/l.lags")
      save=$(echo "$sout" | sed -n 's/.*GB in \([0-9.]*\)s[,;].*/\1/p')
      scrc=$(echo "$sout" | sed -n 's/.*of which \([0-9.]*\) s the CRC32.*/\1/p')
      rm -f "$TMP"/o.*
      out=$(cd "$tree" && PYTHONPATH="$tree" mpirun --allow-run-as-root --oversubscribe -n $n "$PY" -m petsc_ssi \
            -options_file runs/pekeris/small.opts -ssi_output "$TMP/o.h5" -ssi_lags_load "$TMP/l.lags")
      load=$(echo "$out" | sed -n 's/.*loaded from .* in \([0-9.]*\)s (no assembly).*/\1/p')
      check=$(echo "$out" | sed -n 's/.*content checked against its CRC32s (.* GB in \([0-9.]*\) s).*/\1/p')
      echo "ranks $n $tag checksums: save ${save} s (checksums ${scrc:-0} s), load ${load} s + check ${check:-0} s"
    done
  done
done
