#!/usr/bin/env bash
# -ssi_huge_pages on against off in whole runs (the default, auto, is one of the two: off for the lag
# arrays where the machine's balloon reports free pages to its host): each case REPEAT times (default 3) at 1
# and 2 ranks with numpy's transparent-huge-page advice on and off, alternating (on, off, on, off,
# ...) so that a slow spell of the machine hits both, all with -log_view; the table
# (jobscripts/scaling_repeat_table.py, cases named CASE-hpon and CASE-hpoff) gives the fastest and
# median totals, time loops and assembly stages: jobscripts/results/huge_pages.csv and
# <!-- huge_pages:begin/end --> in jobscripts/README.md. jobscripts/first_touch.py measures the
# first writes alone.
#   bash jobscripts/huge_pages_bench.sh [CASES...]      (default: medium; about 3 minutes)
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
CASES=${*:-"medium"}
REPEAT=${REPEAT:-3}
repeat_runs out/bench/huge_pages "$REPEAT" "$CASES" "hpon=-ssi_huge_pages on" "hpoff=-ssi_huge_pages off"
"$PY" jobscripts/scaling_repeat_table.py out/bench/huge_pages huge_pages
