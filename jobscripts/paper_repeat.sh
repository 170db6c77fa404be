#!/usr/bin/env bash
# The paper's Lamb case (runs/pekeris/paper.opts) REPEAT times at 2 ranks with -log_view, one after
# the other, and per run the stages issue 29's targets name: total, BEM assembly, time loop, and in
# it the history sum and the BEM solves (whose time includes waiting for the other rank's history
# sum), and the peak memory over the node. The run-to-run spread of one machine, beside the single
# invocation of flat_bench.sh.
#   bash jobscripts/paper_repeat.sh [REPEAT] [OPTIONS...]   (default 3; about 25 s a run on 2 cores)
# OPTIONS are added to every run's command line (e.g. -ssi_huge_pages off); the logs are named by them.
# CASE=runs/building/ssi-full-bonded.opts runs another options file the same way (its time loop stage:
# 'SSI time loop' in coupled runs).
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
REPEAT=${1:-3}
shift || true
EXTRA=("$@")
TAG=$(echo "${EXTRA[*]:-}" | tr -c 'A-Za-z0-9_\n' '_' | sed 's/^_*//')
CASE=${CASE:-runs/pekeris/paper.opts}
NAME=$(basename "$CASE" .opts)
[ "$CASE" = runs/pekeris/paper.opts ] && NAME=paper
OUT=out/bench/paper_repeat
mkdir -p "$OUT"
"$PY" -m petsc_ssi.app.warmup > /dev/null
echo "| run | total [s] | BEM assembly [s] | time loop [s] | history sum [s] | BEM solves [s] | peak memory, all ranks [GB] |"
echo "|---|---|---|---|---|---|---|"
for r in $(seq 1 "$REPEAT"); do
  log="$OUT/$NAME${TAG:+-$TAG}-r$r.log"
  mpirun --allow-run-as-root --oversubscribe -n 2 "$PY" -m petsc_ssi -options_file "$CASE" \
    -ssi_output "$OUT/$NAME.h5" -ssi_output_overwrite -log_view -memory_view "${EXTRA[@]}" > "$log" 2>&1
  "$PY" - "$log" "$r" <<'PY'
import re, sys
log, r = open(sys.argv[1]).read(), sys.argv[2]
def stage(*names):
    for name in names:
        m = re.search(r"^\s*\d+:\s+" + re.escape(name) + r":\s+(\S+)", log, re.M)
        if m:
            return float(m.group(1))
    raise SystemExit(f"no stage {names} in {sys.argv[1]}")
def event(name):        # summed over the stages it appears in (a coupled run's step-matrix solve is in its assembly)
    return sum(float(t) for t in re.findall(r"^" + name + r"\s+\d+\s+\S+\s+(\S+)", log, re.M))
total = float(re.search(r"^Time \(sec\):\s+(\S+)", log, re.M).group(1))
peak = float(re.search(r"Maximum \(over computational time\) process memory:\s+total (\S+)", log).group(1)) / 1e9
print(f"| {r} | {total:.1f} | {stage('SSI BEM assembly'):.1f} | {stage('SSI BEM time loop', 'SSI time loop'):.1f} | "
      f"{event('SSI_BEM_History'):.1f} | {event('SSI_BEM_Solve'):.2f} | {peak:.2f} |")
PY
done
