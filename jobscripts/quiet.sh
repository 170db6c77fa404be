#!/usr/bin/env bash
# Run a benchmark command on a machine made quiet: every other petsc_ssi, pytest or mpirun process
# (another session's tests, a helper's runs) is paused with SIGSTOP while the command runs and resumed
# with SIGCONT after it, so that the measured walls are an idle machine's. The command's own processes
# carry QUIET_MINE=1 in their environment and are left running. Paused processes lose nothing but time
# (an MPI job paused whole resumes; a test with a wall-clock timeout may fail).
#   bash jobscripts/quiet.sh COMMAND [ARGS...]      e.g.  bash jobscripts/quiet.sh bash jobscripts/calibration_runs.sh
set -uo pipefail
# one quiet command at a time (two would pause each other's processes, each holding its memory): a lock
exec 9> "${TMPDIR:-/tmp}/petsc_ssi-quiet.lock"
if ! flock -n 9; then
  echo "[quiet] another jobscripts/quiet.sh runs: waiting for it to end" >&2
  flock 9
fi
export QUIET_MINE=1
"$@" &
CMD=$!
PAUSED=$(mktemp /tmp/quiet-paused.XXXX)
resume() { while read -r pid; do kill -CONT "$pid" 2>/dev/null; done < "$PAUSED"; rm -f "$PAUSED"; }
trap 'kill "$CMD" 2>/dev/null; resume; exit 130' INT TERM
while kill -0 "$CMD" 2>/dev/null; do
  for pid in $(pgrep -f "petsc_ssi|pytest|mpirun|orted|prterun"); do
    [ "$pid" = "$$" ] && continue
    { tr '\0' '\n' < "/proc/$pid/environ"; } 2>/dev/null | grep -qx 'QUIET_MINE=1' && continue
    grep -qx "$pid" "$PAUSED" || { kill -STOP "$pid" 2>/dev/null && echo "$pid" >> "$PAUSED"; }
  done
  sleep 1
done
wait "$CMD"; rc=$?
echo "[quiet] resumed $(wc -l < "$PAUSED") paused processes" >&2
resume
exit $rc
