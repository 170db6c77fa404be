#!/usr/bin/env bash
# Strong scaling 1 -> 2 ranks measured against this machine's run-to-run spread (issue 13's target:
# 85 % or better on the medium and paper cases): each case REPEAT times (default 3) at 1 and at 2
# ranks, alternating (1, 2, 1, 2, ...) so that a slow spell of the machine hits both, all with
# -log_view; the table (jobscripts/scaling_repeat_table.py) gives each rank count's fastest and
# median total and time loop and the efficiencies T_1 / (2 T_2) of both:
# jobscripts/results/scaling_repeat.csv and <!-- scaling_repeat:begin/end --> in jobscripts/README.md.
#   bash jobscripts/scaling_repeat.sh [CASES...]      (default: medium paper; about 8 minutes,
#                                                      the paper case needs about 13 GB)
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
CASES=${*:-"medium paper"}
REPEAT=${REPEAT:-3}
repeat_runs out/bench/scaling_repeat "$REPEAT" "$CASES" "="
"$PY" jobscripts/scaling_repeat_table.py out/bench/scaling_repeat
