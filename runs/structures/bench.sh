#!/usr/bin/env bash
# Structures benchmark: set-up, assembly, MUMPS factorisation and memory of a frame-and-shell
# building (runs/structures/frame_shell_model.py: 10 storeys, 4 x 4 bays of 6 m, 3.5 m storeys)
# at 1 and 2 ranks with `petsc-ssi static`, from -log_view, -memory_view and /usr/bin/time -v
# of every rank. Then runs/structures/report.py parses the logs into runs/structures/bench.csv
# (+ profile.csv) and rewrites the tables of runs/structures/README.md.
#
#   bash runs/structures/bench.sh                    # from anywhere; ~5 minutes on 2 cores
#   SIZES="2.0 1.0" REPEAT=1 bash runs/structures/bench.sh
#
# Environment (all optional):
#   SIZES     element sizes [m] of the building (default "2.0 1.0 0.75 0.6 0.3":
#             11.8k, 42k, 71k, 109k dofs, and 0.3 m = 396k dofs as a headroom point)
#   RANKS     rank counts (default "1 2")
#   REPEAT    runs per (size, ranks), repeats outermost; the table gives the median of the runs
#             that other jobs left alone (report.py: "other load" <= 0.25 cores), default 5
#   OUT       logs, meshes, profile (default out/structures-bench; out/ is not versioned)
#   LOCKFILE  flock file held for the whole benchmark so that jobs that take the same lock
#             do not run at the same time (default /tmp/ssi_cpu.lock, as jobscripts/; "" = none)
#   CONTROL   1 (default): also run two independent 1-rank jobs of the largest of the issue's
#             sizes (0.6) at the same time, to separate "2 ranks" from "2 busy cores"
#   PROFILE   1 (default): cProfile of one 1-rank run of the 0.6 m model (set-up hot spots)
#   QUIET_MAX before each run, wait up to this many seconds (default 30; 0 = never) for a 1-s
#             window in which the machine is idle: other jobs on a shared machine come and go
#
# Per run OUT/e<size>-np<ranks>-r<k>.*: .log (-log_view), .out (stdout/stderr: the application's
# lines, -memory_view, MUMPS statistics -ssi_fem_mat_mumps_icntl_4 2), .wall.time (/usr/bin/time -v
# of mpirun: wall time with start-up), .rank<r>.time (/usr/bin/time -v of rank r: its max RSS),
# .stat (the machine's /proc/stat cpu line before and after: report.py subtracts the run's own
# CPU time to show how busy other jobs kept the cores, column "other load"), .rev (git revision +
# hash of the uncommitted diff of petsc_ssi/ at the start of the run).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/../../jobscripts/bench_env.sh"   # cd repo root, PY, env
SIZES=${SIZES:-"2.0 1.0 0.75 0.6 0.3"}
RANKS=${RANKS:-"1 2"}
REPEAT=${REPEAT:-5}
OUT=${OUT:-out/structures-bench}
LOCKFILE=${LOCKFILE-/tmp/ssi_cpu.lock}
CONTROL=${CONTROL:-1}
PROFILE=${PROFILE:-1}
QUIET_MAX=${QUIET_MAX:-30}
CONTROL_SIZE=0.6
GEOM=(--storeys 10 --bays-x 4 --bays-y 4 --bay 6 --height 3.5)

# The model: concrete everywhere (E 30 GPa, nu 0.2, rho 2500), 0.2 m slabs, 0.4 x 0.4 columns,
# 0.3 x 0.5 beams (0.5 deep), column feet fixed, 100 kN along x at the roof corner.
OPTS=(
  -ssi_problem fem
  -ssi_fem_parts slabs,columns,beams
  -ssi_fem_part_slabs_element shell -ssi_fem_part_slabs_thickness 0.2
  -ssi_fem_part_slabs_E 30e9 -ssi_fem_part_slabs_nu 0.2 -ssi_fem_part_slabs_rho 2500
  -ssi_fem_part_columns_element frame -ssi_fem_part_columns_section 0.4,0.4
  -ssi_fem_part_columns_E 30e9 -ssi_fem_part_columns_nu 0.2 -ssi_fem_part_columns_rho 2500
  -ssi_fem_part_beams_element frame -ssi_fem_part_beams_section 0.3,0.5
  -ssi_fem_part_beams_E 30e9 -ssi_fem_part_beams_nu 0.2 -ssi_fem_part_beams_rho 2500
  -ssi_fem_fixed base
  -ssi_fem_point_load top,1e5,0,0
  -ssi_receivers group:top
  -ssi_output ""
  -ssi_fem_mat_mumps_icntl_4 2
)

if [ -n "$LOCKFILE" ]; then
  exec 9>"$LOCKFILE"
  echo "[structures-bench] waiting for $LOCKFILE"
  flock 9
fi
mkdir -p "$OUT"
rm -f "$OUT"/*.log "$OUT"/*.out "$OUT"/*.time "$OUT"/*.stat "$OUT"/*.wait "$OUT"/*.rev "$OUT"/*.prof "$OUT"/*.json
{ echo "# before: $(date -u +%FT%TZ)"; uptime; } > "$OUT/load.txt"   # other jobs make timings noisy

# wait_quiet: wait (at most QUIET_MAX s) for a 1-s window in which the machine is <= 0.1 cores busy
# (other engineers' jobs come and go on this shared machine); the wait is recorded in the .stat file
wait_quiet() {
  local t0=$SECONDS a b
  while [ $((SECONDS - t0)) -lt "$QUIET_MAX" ]; do
    a=$(head -1 /proc/stat); sleep 1; b=$(head -1 /proc/stat)
    if awk -v a="$a" -v b="$b" -v hz="$(getconf CLK_TCK)" 'BEGIN { split(a, x); split(b, y);
         busy = (y[2]+y[3]+y[4]+y[7]+y[8]) - (x[2]+x[3]+x[4]+x[7]+x[8]); exit !(busy / hz <= 0.1) }'; then
      break
    fi
  done
  echo "# waited $((SECONDS - t0)) s for a quiet machine"
}

# run BASE NRANKS MESH: one `petsc-ssi static` run, each rank under /usr/bin/time -v
run() {
  local base=$1 n=$2 msh=$3
  [ "$QUIET_MAX" -gt 0 ] && wait_quiet > "$base.wait"
  # the application's version (other engineers commit while a benchmark runs): read-only git
  echo "$(git rev-parse --short HEAD 2>/dev/null)+$(git diff HEAD -- petsc_ssi 2>/dev/null | md5sum | cut -c1-8)" \
    > "$base.rev"
  head -1 /proc/stat > "$base.stat"      # busy CPU of the whole machine before/after: other jobs
  /usr/bin/time -v -o "$base.wall.time" \
    mpirun --allow-run-as-root -n "$n" \
      sh -c 'exec /usr/bin/time -v -o "$0.rank$OMPI_COMM_WORLD_RANK.time" "$@"' "$base" \
      "$PY" -m petsc_ssi static "${OPTS[@]}" -ssi_fem_mesh "$msh" -log_view ":$base.log" -memory_view \
    > "$base.out" 2>&1
  head -1 /proc/stat >> "$base.stat"
}

for e in $SIZES; do
  "$PY" runs/structures/frame_shell_model.py "${GEOM[@]}" --elem "$e" --out "$OUT/building-e$e.msh" \
    > "$OUT/building-e$e.json"
  echo "[structures-bench] mesh e=$e: $(cat "$OUT/building-e$e.json")"
done

first=$(echo $SIZES | awk '{print $1}')
echo "[structures-bench] warm-up (file cache, numba cache), not recorded"
run "$OUT/warmup" 1 "$OUT/building-e$first.msh"
rm -f "$OUT"/warmup.*

# repeats outermost: a burst of other jobs then hits every case about equally
for r in $(seq 1 "$REPEAT"); do
  for e in $SIZES; do
    for n in $RANKS; do
      base="$OUT/e$e-np$n-r$r"
      echo "[structures-bench] repeat $r: e=$e np=$n -> $base.*"
      run "$base" "$n" "$OUT/building-e$e.msh"
    done
  done
done

if [ "$CONTROL" = 1 ] && [ -f "$OUT/building-e$CONTROL_SIZE.msh" ]; then
  # two independent 1-rank jobs at once: what two busy cores do to one rank's times
  for r in $(seq 1 "$REPEAT"); do
    echo "[structures-bench] control: two 1-rank jobs of e=$CONTROL_SIZE at once, repeat $r"
    [ "$QUIET_MAX" -gt 0 ] && wait_quiet > /dev/null
    QUIET_MAX=0 run "$OUT/e$CONTROL_SIZE-np1x2-r$r-a" 1 "$OUT/building-e$CONTROL_SIZE.msh" &
    QUIET_MAX=0 run "$OUT/e$CONTROL_SIZE-np1x2-r$r-b" 1 "$OUT/building-e$CONTROL_SIZE.msh" &
    wait
  done
fi

if [ "$PROFILE" = 1 ] && [ -f "$OUT/building-e$CONTROL_SIZE.msh" ]; then
  echo "[structures-bench] cProfile of one 1-rank run of e=$CONTROL_SIZE"
  "$PY" -m cProfile -o "$OUT/profile-e$CONTROL_SIZE.prof" -m petsc_ssi static "${OPTS[@]}" \
    -ssi_fem_mesh "$OUT/building-e$CONTROL_SIZE.msh" > "$OUT/profile-e$CONTROL_SIZE.out" 2>&1
fi

{ echo "# after: $(date -u +%FT%TZ)"; uptime; } >> "$OUT/load.txt"
"$PY" runs/structures/report.py --logs "$OUT"
