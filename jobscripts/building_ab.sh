#!/usr/bin/env bash
# A/B of two versions of the code on the paper's building on the uniform 72 m grid (building_uniform.sh's
# uniform-72 options) to T_END (default 0.5 s: 100 steps past the build), each version in its own git
# worktree with its own numba cache, the two alternated REPEAT times (default 2) so that a slow spell of
# the machine hits both, on RANKS ranks (default 2). Prints per run the -log_view events that split the
# time (kernels, factorisation, interface matrices, history, its blocks, the step solves) and the total.
#   bash jobscripts/quiet.sh bash jobscripts/building_ab.sh REV_A REV_B
#   e.g. bash jobscripts/quiet.sh bash jobscripts/building_ab.sh 4ae54ea f63e559
# EXTRA: options added to both (e.g. EXTRA="-ssi_history_block 16"); OUT: where the logs go
# (default /tmp/building_ab); TABLE_ONLY=1: print the table of OUT's logs again, no runs.
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
A=${1:?REV_A}; B=${2:?REV_B}
T_END=${T_END:-0.5}; REPEAT=${REPEAT:-2}; RANKS=${RANKS:-2}; EXTRA=${EXTRA:-}; OUT=${OUT:-/tmp/building_ab}
mkdir -p "$OUT"
ROOT=$PWD
ARGS=(-options_file runs/building/ssi-full-bonded.opts -ssi_mesh grid -ssi_mesh_h 1.2 -ssi_mesh_patch 7.2,5.4
      -ssi_load_group box:14.9,15.1,-0.1,0.1 -ssi_load_p0 694.4444444444445 -ssi_lag_store toeplitz
      -ssi_mesh_size 72,73.2 -ssi_t_end "$T_END" -ssi_output_stride 0 -log_view)
if [[ -z "${TABLE_ONLY:-}" ]]; then
  declare -A WT
  for rev in "$A" "$B"; do
    d=$(mktemp -d /tmp/petsc_ssi-ab.XXXX)
    git worktree add --detach "$d" "$rev" > /dev/null
    WT[$rev]=$d
    (cd "$d" && NUMBA_CACHE_DIR="$d/.numba_cache" "$PY" -m petsc_ssi.app.warmup > /dev/null)
  done
  # shellcheck disable=SC2064
  trap "for d in ${WT[*]}; do git -C '$ROOT' worktree remove --force \$d; done" EXIT
  for i in $(seq 1 "$REPEAT"); do
    for rev in "$A" "$B"; do
      d=${WT[$rev]}
      echo "[ab] $rev, run $i -> $OUT/$rev-r$i.log" >&2
      # shellcheck disable=SC2086
      (cd "$d" && NUMBA_CACHE_DIR="$d/.numba_cache" mpirun --allow-run-as-root --oversubscribe -n "$RANKS" \
         "$PY" -m petsc_ssi "${ARGS[@]}" $EXTRA -ssi_output "$OUT/$rev.h5" -ssi_output_overwrite \
         > "$OUT/$rev-r$i.log" 2>&1)
    done
  done
fi
# the table from the logs (TABLE_ONLY=1: from OUT's logs of an earlier call, no runs)
ev() { awk -v e="$1" -v n="${2:-}" '$1 == e && (n == "" || $2 == n) {print $4; exit}' "$log"; }
printf '| run | version | SSI_BEM_Toeplitz [s] | SSI_BEM_Factor [s] | SSI_Capacitance [s] | SSI_BEM_History [s] | SSI_BEM_HistFFTBlock [s] | step solves [s] | total [s] |\n'
printf '|---|---|---|---|---|---|---|---|---|\n'
for i in $(seq 1 "$REPEAT"); do
  for rev in "$A" "$B"; do
    log="$OUT/$rev-r$i.log"
    steps=$(awk '$1 == "SSI_BEM_History" {print $2; exit}' "$log")
    printf '| %s | %s | %s | %s | %s | %s | %s | %s | %s |\n' "$i" "$rev" "$(ev SSI_BEM_Toeplitz)" \
      "$(ev SSI_BEM_Factor)" "$(ev SSI_Capacitance)" "$(ev SSI_BEM_History)" "$(ev SSI_BEM_HistFFTBlock)" \
      "$(ev SSI_BEM_Solve "$steps")" "$(awk '/^Time \(sec\):/ {print $3; exit}' "$log")"
  done
done
