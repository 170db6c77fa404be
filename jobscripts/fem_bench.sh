#!/usr/bin/env bash
# Benchmark of the structural FEM (issue 4): assembly, factorisation and time
# stepping of the paper's foundation block (400 hex8, meshes/foundation.geo) and
# of a 10x larger brick mesh (box 20 x 20 x 10 = 4000 hex8, same block), on 1 and
# 2 ranks, MUMPS (factorise once) vs CG + hypre BoomerAMG (and CG + Jacobi,
# cheap while D is mass-dominated), from -log_view.
# The table goes into runs/foundation/README.md (jobscripts/parse_fem_log.py).
#
#   bash jobscripts/fem_bench.sh            # from the repository root
#   STEPS=400 bash jobscripts/fem_bench.sh  # more time steps
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
STEPS=${STEPS:-200}
DT=2.5e-4
TEND=$("$PY" -c "print($STEPS * $DT)")
LOGS=out/bench/fem
mkdir -p "$LOGS"
rm -f "$LOGS"/*.log
uptime > "$LOGS/load.txt"     # other jobs on the machine make the timings noisy

declare -A MESH=(
  [block400]="-ssi_fem_mesh meshes/foundation.geo"
  [box4000]="-ssi_fem_mesh box -ssi_fem_box_cells 20,20,10"
)
declare -A SOLVER=(
  [mumps]="-ssi_fem_solver direct"
  [cg_hypre]="-ssi_fem_solver iterative"
  [cg_jacobi]="-ssi_fem_solver iterative -ssi_fem_pc_type jacobi"
)
for mesh in block400 box4000; do
  for solver in mumps cg_hypre cg_jacobi; do
    for np in 1 2; do
      log="$LOGS/${mesh}_${solver}_np${np}.log"
      echo "[bench] $mesh $solver np=$np -> $log"
      mpirun --allow-run-as-root -n "$np" "$PY" -m petsc_ssi \
        -options_file runs/foundation/block-fixed.opts ${MESH[$mesh]} ${SOLVER[$solver]} \
        -ssi_dt "$DT" -ssi_t_end "$TEND" -ssi_output "" -log_view ":$log" > "$log.out"
    done
  done
done
uptime >> "$LOGS/load.txt"
"$PY" jobscripts/parse_fem_log.py "$LOGS"/*.log --csv "$LOGS/fem_bench.csv" \
  --load "$LOGS/load.txt" --readme runs/foundation/README.md
