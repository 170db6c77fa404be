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
#   today-smooth, today-fine-smooth, uniform-36-area-smooth, uniform-72-area-smooth  (not by default) today's load
#                   with a smooth history instead of the 25 ms box, a 0.1 s Hann pulse p0 sin^2(pi t / 0.1 s)
#                   (-ssi_load_history table, OUT/hann100ms.txt, rows every 1 ms), every lag exact, on today's mesh,
#                   today's mesh refined (-ssi_mesh_params g=1.15,hm=1.5,hr=1.0,hq=1.0: cells of at most 1.5 m) and
#                   the building's uniform grid of 36 m and 72 m (the load as an area); the exact answer is the
#                   tabulated pulse's (its ramps' responses summed)
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
GA0=("${G[@]}" -ssi_mesh_h 1.2 -ssi_mesh_patch 7.2,5.4 -ssi_load_group "" -ssi_load_area 14,15,-0.5,0.5)
GA=("${GA0[@]}" -ssi_mesh_size 72,73.2)
X=(-ssi_interp none)
# the smooth load (building_uniform.sh's): p0 sin^2(pi t / T), T = 0.1 s, tabulated every 1 ms, zero after T
"$PY" -c "import numpy as np; t = np.r_[np.arange(0, 0.1005, 0.001), 10.0]; v = np.where(t <= 0.1, np.sin(np.pi * t / 0.1) ** 2, 0.0)
np.savetxt('$OUT/hann100ms.txt', np.c_[t, v], fmt='%.6g', header='t [s]  p / p0 [-]: a 0.1 s Hann pulse')"
H=(-ssi_load_history table -ssi_load_table "$OUT/hann100ms.txt")
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
    today-smooth) sampled_run today-smooth "${S[@]}" "${X[@]}" "${H[@]}" ;;
    today-fine-smooth) sampled_run today-fine-smooth "${S[@]}" "${X[@]}" "${H[@]}" -ssi_mesh_params g=1.15,hm=1.5,hr=1.0,hq=1.0 ;;
    uniform-36-area-smooth) sampled_run uniform-36-area-smooth "${S[@]}" "${GA0[@]}" -ssi_mesh_size 36,37.2 "${X[@]}" "${H[@]}" ;;
    uniform-72-area-smooth) sampled_run uniform-72-area-smooth "${S[@]}" "${GA[@]}" "${X[@]}" "${H[@]}" ;;
    *) echo "unknown run $r" >&2; exit 2 ;;
  esac
done
tables_or_print out/bench/building_soil_exact jobscripts/building_soil_exact.py
