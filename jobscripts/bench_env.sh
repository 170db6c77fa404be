# Environment of the benchmark scripts (sourced, not run): repository root as the
# working directory, the project's python, Debian's PETSc/SLEPc unless set, one
# BLAS thread per rank, OpenMPI as root, the numba cache make and every direct call share
# (~/.cache/petsc_ssi/numba/<hash of the sources>, README.md; NUMBA_CACHE_DIR if set: kept).
cd "$(dirname "${BASH_SOURCE[0]}")/.."
PY=${PY:-.venv/bin/python}
case $PY in /*) ;; */*) PY=$PWD/$PY ;; esac   # (absolute: the scripts cd into worktrees and run dirs)
export PETSC_DIR=${PETSC_DIR:-/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real}
export SLEPC_DIR=${SLEPC_DIR:-/usr/lib/slepcdir/slepc3.18/x86_64-linux-gnu-real}
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# before_worktree COMMIT [CLEANUP]: the code at COMMIT in a git worktree $WT for before/after
# benchmarks (removed on exit, after the shell command CLEANUP), ROOT the repository; the old code's
# numba kernels are cached apart in $BEFORE_CACHE (the worktree's files are new to numba's index:
# without its own cache the first timed run would compile them); both caches are warmed.
before_worktree() {
  ROOT=$PWD
  WT=$(mktemp -d /tmp/petsc_ssi-before.XXXX)
  git worktree add --detach "$WT" "$1" > /dev/null
  # shellcheck disable=SC2064
  trap "git worktree remove --force '$WT'; ${2:-:}" EXIT
  export BEFORE_CACHE="$WT/.numba_cache"
  (cd "$WT" && NUMBA_CACHE_DIR="$BEFORE_CACHE" "$PY" -m petsc_ssi.app.warmup) && "$PY" -m petsc_ssi.app.warmup
}

# repeat_runs OUT REPEAT "CASES" VARIANT...: each case (runs/pekeris/CASE.opts) REPEAT times at 1 and at
# 2 ranks under each VARIANT ("TAG=OPTIONS"; "=" the case as it stands), variants and rank counts
# alternating within a repeat so that a slow spell of the machine hits them all, with -log_view:
# OUT/CASE[-TAG]-nN-rI.log (jobscripts/scaling_repeat_table.py reads them). Warms the numba cache first.
repeat_runs() {
  local out=$1 repeat=$2 cases=$3
  shift 3
  mkdir -p "$out"
  "$PY" -m petsc_ssi.app.warmup
  local case i v n tag opts name log
  for case in $cases; do
    for i in $(seq 1 "$repeat"); do
      for v in "$@"; do
        tag=${v%%=*}
        opts=${v#*=}
        name=$case${tag:+-$tag}
        for n in 1 2; do
          log="$out/$name-n$n-r$i.log"
          echo "[bench] $name${opts:+ ($opts)} on $n rank(s), run $i -> $log"
          # shellcheck disable=SC2086
          mpirun --allow-run-as-root --oversubscribe -n "$n" "$PY" -m petsc_ssi -options_file "runs/pekeris/$case.opts" \
            $opts -ssi_output "$out/$name-n$n-r$i.h5" -ssi_output_overwrite -ssi_output_stride 0 -log_view > "$log" 2>&1
        done
      done
    done
  done
}

# sampled_run NAME ARGS...: one petsc_ssi run on $RANKS ranks into $OUT/NAME.{h5,log} with -log_view and -memory_view,
# its ranks' resident memory sampled every 2 s ("# sampled peak RSS over the ranks" at the log's end), the load
# average before and after; MIN_FREE_GB > 0 stops the run when the machine's available memory falls below it
# (toeplitz_bench.sh, building_uniform.sh)
sampled_run() {
  local name=$1
  shift
  echo "[bench] $name on $RANKS rank(s) -> $OUT/$name.log"
  echo "# load average before the run (other users of the machine): $(cat /proc/loadavg)" > "$OUT/$name.log"
  mpirun --allow-run-as-root --oversubscribe -n "$RANKS" "$PY" -m petsc_ssi "$@" -ssi_output "$OUT/$name.h5" \
    -ssi_output_overwrite -ssi_output_stride 0 -log_view -memory_view >> "$OUT/$name.log" 2>&1 &
  local pid=$! peak=0 rss avail
  while kill -0 "$pid" 2>/dev/null; do     # the ranks' resident memory (children of this mpirun), and the guard
    rss=$( (ps --ppid "$pid" -o rss= || true) | awk '{s += $1} END {print s + 0}')   # (ps fails once the ranks end)
    if (( rss > peak )); then peak=$rss; fi
    avail=$(awk '/MemAvailable/ {print int($2 / 1048576)}' /proc/meminfo)
    if (( ${MIN_FREE_GB:-0} > 0 && avail < MIN_FREE_GB )); then
      echo "# stopped by the script: the machine's available memory fell to $avail GB (MIN_FREE_GB=${MIN_FREE_GB:-0})," \
        "the ranks held $(awk -v k="$rss" 'BEGIN {printf "%.2f", k / 1e6}') GB" >> "$OUT/$name.log"
      kill "$pid"
    fi
    sleep 2
  done
  wait "$pid" || true
  echo "# sampled peak RSS over the ranks: $(awk -v k="$peak" 'BEGIN {printf "%.2f", k / 1e6}') GB" >> "$OUT/$name.log"
  echo "# load average after the run: $(cat /proc/loadavg)" >> "$OUT/$name.log"
}

# tables_or_print DEFAULT_OUT SCRIPT: the tables of SCRIPT from $OUT, written into the READMEs and CSVs when $OUT is the
# script's default directory, printed only for another $OUT (building_uniform.sh, building_soil_exact.sh)
tables_or_print() {
  if [[ "$OUT" == "$1" ]]; then
    "$PY" "$2" "$OUT"
  else
    "$PY" "$2" "$OUT" --print
  fi
}
