#!/usr/bin/env bash
# The step matrix's mirror-symmetric blocks (petsc_ssi/bem/mirror.py) and the toeplitz store's lag files on the
# paper's building over the uniform 72 m grid (jobscripts/building_uniform.sh's uniform-72), on RANKS ranks
# (default 2), with -log_view:
#   mirror      T_END (default 0.1 s) with -ssi_step_mirror auto (the blocks)
#   off         the same with -ssi_step_mirror off (the step matrix and the region's matrix as they are)
#   save, load  LAGS_T_END (default 0.05 s) with -ssi_lags_save, then the same with -ssi_lags_load
#   load-other  the same file loaded on OTHER_RANKS ranks (default 1): the kernels are frequency-major in the
#               file, any rank count reads them (petsc_ssi/bem/lagstore.py)
# Then jobscripts/step_mirror_check.py prints the factors' entries, the factorisations' and the step solves'
# seconds, the interface columns' LU and solves, each run's largest bem_residual, and the largest difference of
# every recorded field of mirror against off and of load and load-other against save over the field's largest
# value (of this invocation's RUNS).
#   bash jobscripts/quiet.sh bash jobscripts/step_mirror_check.sh        (OUT=... another directory;
#   RUNS="save load load-other" a subset: save before the loads)
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
RANKS=${RANKS:-2}
OUT=${OUT:-out/bench/step_mirror}
T_END=${T_END:-0.1}
LAGS_T_END=${LAGS_T_END:-0.05}
OTHER_RANKS=${OTHER_RANKS:-1}
RUNS=${RUNS:-"mirror off save load load-other"}
mkdir -p "$OUT"
"$PY" -m petsc_ssi.app.warmup > /dev/null
U=(-options_file runs/building/ssi-full-bonded.opts -ssi_mesh grid -ssi_mesh_h 1.2 -ssi_mesh_patch 7.2,5.4
   -ssi_load_group box:14.9,15.1,-0.1,0.1 -ssi_load_p0 694.4444444444445 -ssi_lag_store toeplitz
   -ssi_mesh_size 72,73.2 -ssi_output_overwrite -log_view)
run() {
  local n=$1 name=$2
  shift 2
  echo "[bench] $name on $n rank(s) -> $OUT/$name.log"
  mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi "${U[@]}" -ssi_output "$OUT/$name.h5" "$@" \
    > "$OUT/$name.log" 2>&1
}
for r in $RUNS; do
  case $r in
    mirror) run "$RANKS" mirror -ssi_t_end "$T_END" ;;
    off) run "$RANKS" off -ssi_t_end "$T_END" -ssi_step_mirror off ;;
    save) rm -f "$OUT/lags" "$OUT/lags.json"
          run "$RANKS" save -ssi_t_end "$LAGS_T_END" -ssi_lags_save "$OUT/lags" ;;
    load) run "$RANKS" load -ssi_t_end "$LAGS_T_END" -ssi_lags_load "$OUT/lags" ;;
    load-other) run "$OTHER_RANKS" load-other -ssi_t_end "$LAGS_T_END" -ssi_lags_load "$OUT/lags" ;;
    *) echo "unknown run $r" >&2; exit 2 ;;
  esac
done
"$PY" jobscripts/step_mirror_check.py "$OUT" "$RUNS"
