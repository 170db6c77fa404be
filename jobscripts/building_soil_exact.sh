#!/usr/bin/env bash
# The building's soil alone (no structure) under the building's load, against the exact solution of the
# half-space (issue 41's building item: which soil mesh is the accurate one). Every run is
# runs/building/ssi-common.opts with -ssi_problem bem (the soil, the load p0 (H(t) - H(t - 0.025 s)), the
# receivers on y = 0, dt = 5 ms, 1.5 s, Chebyshev far lags from T_L = 0.27 s), on RANKS ranks (default 2):
#   today           meshes/building_soil.geo as today: 36 m x 36 m graded (1-3.09 m cells), the 1 m x 1 m
#                   patch centred at x = 14.5 m, p0 = 1000 N/m^2; dense lags
#   uniform-36-1m   a uniform grid of 1 m cells, 36 m x 37 m, whose lines pass through the same patch
#                   (-ssi_mesh_patch 7,4.5: x = 7 + k, y = 4.5 + k); toeplitz
#   uniform-72-1m   the same, 72 m x 73 m
#   today-load15    the graded mesh with the uniform building grids' load: the 1.2 m cell centred at x = 15 m,
#                   p0 = 1000/1.44 N/m^2 (building_uniform.sh)
#   uniform-36      the building's uniform grid: 1.2 m cells (0.6 m nodes, the slab's), 36 x 37.2 m, that load
#   uniform-72      the same, 72 x 73.2 m
#   uniform-36-h06  0.6 m cells (0.3 m nodes), 36 x 37.2 m, that load on its 4 cells, dt = 2.5 ms (beta = c_p dt / l
#                   as at 1.2 m and 5 ms: 1.73)
#   uniform-72-area the building's uniform grid (1.2 m cells, 72 x 73.2 m) with today's load as it is: the 1 m x 1 m
#                   square at x = 14.5 m as an area load (-ssi_load_area 14,15,-0.5,0.5: integrated over the square,
#                   which no cell of this grid holds)
#   *-exact         (today-exact, uniform-72-exact, uniform-72-area-exact) the same without interpolated far lags
#                   (-ssi_interp none: every lag exact, 103 on the 36 m mesh, 207 on the 72 m grid)
# jobscripts/building_soil_exact.py then compares each run's receivers with the exact surface displacement of
# its own load (petsc_ssi.analytic.pekeris.patch_displacement: the point-load solution integrated over the
# patch, general nu; the box history as the difference of two steps) and writes the table into
# runs/building/README.md, runs/building/building_soil_exact.csv and building_soil_exact.png.
#   bash jobscripts/building_soil_exact.sh
#   RUNS="today uniform-36" OUT=/tmp/x bash jobscripts/building_soil_exact.sh   (a subset, printed only)
# The loads of the runs are also in building_soil_exact.py's RUNS (it checks the logs' loaded element counts).
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
RANKS=${RANKS:-2}
OUT=${OUT:-out/bench/building_soil_exact}
RUNS=${RUNS:-"today today-exact uniform-36-1m uniform-72-1m today-load15 uniform-36 uniform-72 uniform-72-exact
      uniform-36-h06 uniform-72-area uniform-72-area-exact"}
T_END=${T_END:-}
mkdir -p "$OUT"
"$PY" -m petsc_ssi.app.warmup > /dev/null
S=(-options_file runs/building/ssi-common.opts -ssi_problem bem ${T_END:+-ssi_t_end "$T_END"})
P15=(-ssi_load_p0 694.4444444444445)          # 1000 N over the 1.44 m^2 cell
G=(-ssi_mesh grid -ssi_lag_store toeplitz)
G1=("${G[@]}" -ssi_mesh_h 1.0 -ssi_mesh_patch 7,4.5 -ssi_load_group box:14.4,14.6,-0.1,0.1)
G12=("${G[@]}" -ssi_mesh_h 1.2 -ssi_mesh_patch 7.2,5.4 -ssi_load_group box:14.9,15.1,-0.1,0.1 "${P15[@]}")
GA=("${G[@]}" -ssi_mesh_h 1.2 -ssi_mesh_patch 7.2,5.4 -ssi_mesh_size 72,73.2 -ssi_load_group "" -ssi_load_area 14,15,-0.5,0.5)
X=(-ssi_interp none)
G06=("${G[@]}" -ssi_mesh_h 0.6 -ssi_mesh_patch 7.2,5.4 -ssi_load_group box:14.41,15.59,-0.59,0.59 "${P15[@]}"
     -ssi_dt 2.5e-3)
for r in $RUNS; do
  case $r in
    today) sampled_run today "${S[@]}" ;;
    today-exact) sampled_run today-exact "${S[@]}" "${X[@]}" ;;
    uniform-36-1m) sampled_run uniform-36-1m "${S[@]}" "${G1[@]}" -ssi_mesh_size 36,37 ;;
    uniform-72-1m) sampled_run uniform-72-1m "${S[@]}" "${G1[@]}" -ssi_mesh_size 72,73 ;;
    today-load15) sampled_run today-load15 "${S[@]}" -ssi_mesh_params xl=15,w=1.2 "${P15[@]}" ;;
    uniform-36) sampled_run uniform-36 "${S[@]}" "${G12[@]}" -ssi_mesh_size 36,37.2 ;;
    uniform-72) sampled_run uniform-72 "${S[@]}" "${G12[@]}" -ssi_mesh_size 72,73.2 ;;
    uniform-72-exact) sampled_run uniform-72-exact "${S[@]}" "${G12[@]}" -ssi_mesh_size 72,73.2 "${X[@]}" ;;
    uniform-72-area) sampled_run uniform-72-area "${S[@]}" "${GA[@]}" ;;
    uniform-72-area-exact) sampled_run uniform-72-area-exact "${S[@]}" "${GA[@]}" "${X[@]}" ;;
    uniform-36-h06) sampled_run uniform-36-h06 "${S[@]}" "${G06[@]}" -ssi_mesh_size 36,37.2 ;;
    *) echo "unknown run $r" >&2; exit 2 ;;
  esac
done
tables_or_print out/bench/building_soil_exact jobscripts/building_soil_exact.py
