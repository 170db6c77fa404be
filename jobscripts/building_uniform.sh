#!/usr/bin/env bash
# The paper's building on a uniform soil grid on the toeplitz lag store (issue 41's building item), against
# today's building (runs/building/ssi-full-bonded.opts: the graded 36 m x 36 m soil of
# meshes/building_soil.geo, dense lag matrices), on RANKS ranks (default 2), with -log_view and -memory_view:
#   today          runs/building/ssi-full-bonded.opts as it is (1 m x 1 m load patch centred at x = 14.5 m)
#   today-load15   the same graded mesh, but the load of the uniform grids: one 1.2 m x 1.2 m cell centred at
#                  x = 15.0 m (-ssi_mesh_params xl=15,w=1.2), p0 = 1000 / 1.44 N/m^2 (the same 1 kN resultant).
#                  A uniform grid whose nodes are the slab's 0.6 m shell nodes has its cell edges on
#                  x = 1.2 k and y = 0.6 + 1.2 k: no cell holds the 1 m patch at x = 14.5 (runs/building/README.md)
#   uniform-36     -ssi_mesh grid 36 x 37.2 m of equal 1.2 m nine-node cells (node spacing 0.6 m = the slab's
#                  shell nodes; y edges at +-18.6 so that +-5.4 are cell edges), toeplitz, the same load
#   uniform-72     the same grid, 72 x 73.2 m (at least twice today's extent in each direction), toeplitz
#   today-exact    today without interpolated far lags (-ssi_interp none: all 103 lags exact, dense)
#   uniform-72-area  uniform-72 with today's load as it is: the 1 m x 1 m square at x = 14.5 m as an area load
#                  (-ssi_load_area 14,15,-0.5,0.5, sources/area.py: integrated over the square, which no cell holds)
#   uniform-72-area-exact, uniform-36-area-exact  the same on 72 m and 36 m, every lag exact (-ssi_interp none;
#                  207 and 103 lags): with today-exact, the split of the difference to today into the far lags'
#                  interpolation, the cells and the extent (runs/building/README.md)
#   today-fine     (not by default) today's graded mesh refined, every lag exact (-ssi_mesh_params
#                  g=1.15,hm=1.5,hr=1.0,hq=1.0: cells of at most 1.5 m, the slab's 1.2 m and the 1 m patch kept; 9333 DOFs):
#                  against today-exact, how far today's own answer moves when its mesh is refined
#   today-smooth, uniform-36-smooth, uniform-72-smooth, today-fine-smooth  (not by default) today-exact,
#                  uniform-36-area-exact, uniform-72-area-exact and today-fine with a smooth load history instead of
#                  the 25 ms box: a 0.1 s Hann pulse, p0 sin^2(pi t / 0.1 s) (-ssi_load_history table, OUT/hann100ms.txt),
#                  whose waves (up to about 20 Hz: shear waves of 5 m and longer) the cells resolve
#   uniform-108-smooth (not by default) uniform-72-smooth on a 108 x 109.2 m grid (three times today's extent):
#                  whether 72 m is far enough for the building's response (extent 108 m vs 72 m)
#   uniform-72-area-rule (not by default) uniform-72-area with the paper's rule for the far lags (T_L = 1.5 r / c_s
#                  at the farthest receiver, r = 24.5 m: 0.3675 s; one anchor every 5 steps: k = 27; what
#                  -ssi_interp auto chose on this grid before it kept every lag exact on the toeplitz store) instead of
#                  ssi-common.opts' T_L and k
#   today-smooth-dt2, uniform-36-smooth-dt2 (not by default) today-smooth and uniform-36-smooth with half the step
#                  (-ssi_dt 2.5e-3, 600 steps): how far the time step moves each
#   today-load15-smooth, uniform-36-load15-smooth (not by default) the Hann pulse on the 1.2 m cell at x = 15 m
#                  (today-load15's and uniform-36's load, held by a cell on both meshes), every lag exact
#   uniform-72-fullrank (not by default) uniform-72 with the step matrix's MUMPS LU in full rank (-ssi_step_blr 0;
#                  by default, from 20 000 DOFs on, it is block low-rank at 1e-15 and checked: bem/march.py)
#   uniform-72-fast  (not by default) uniform-72 with FAST (default: multi-linear far lags from the same
#                  T_L and k, kept transforms in single precision): what the history sum's options save
#   uniform-72-blr (not by default) uniform-72 with the step matrix's MUMPS LU in block low-rank form (BLR:
#                  -ssi_bem_mat_mumps_icntl_35 2 -ssi_bem_mat_mumps_cntl_7 $BLR_EPS, default 1e-12): the factors,
#                  the interface columns and the step solves cheaper, the answer moved by about the dropping threshold
#   estimate       (not by default) petsc-ssi estimate of uniform-36 and uniform-72 -> OUT/uniform-36.estimate,
#                  OUT/uniform-72.estimate
#   estimate-smooth (not by default) petsc-ssi estimate of uniform-72-smooth and uniform-108-smooth ->
#                  OUT/uniform-72-smooth.estimate, OUT/uniform-108-smooth.estimate
#   check          (not by default) uniform-36's first 6 steps, dense and toeplitz: the store's exactness on this
#                  coupled case (every recorded series' largest difference over the largest value of its kind)
# The far lags are interpolated as in today's run (Chebyshev from T_L = 0.27 s, k = 20: ssi-common.opts).
# Then jobscripts/building_uniform_table.py writes the tables (walls, stages, memory; receivers against
# today's) into runs/building/README.md and jobscripts/README.md and the CSVs under runs/building/.
#   bash jobscripts/building_uniform.sh
#   RUNS="uniform-72" bash jobscripts/building_uniform.sh      (a subset; T_END=0.05 for a short check;
#   OUT=... another directory, whose tables are printed, not written; EXTRA="-ssi_toeplitz_precision single" options added to the toeplitz runs)
# Each run's log ends with its ranks' resident memory sampled every 2 s ("# sampled peak RSS over the ranks").
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
RANKS=${RANKS:-2}
OUT=${OUT:-out/bench/building_uniform}
RUNS=${RUNS:-"today today-load15 uniform-36 uniform-72 today-exact uniform-72-area uniform-72-area-exact
      uniform-36-area-exact"}
T_END=${T_END:-}
EXTRA=${EXTRA:-}
FAST=${FAST:-"-ssi_interp linear -ssi_toeplitz_precision single"}
BLR_EPS=${BLR_EPS:-1e-12}
mkdir -p "$OUT"
"$PY" -m petsc_ssi.app.warmup > /dev/null
B=(-options_file runs/building/ssi-full-bonded.opts ${T_END:+-ssi_t_end "$T_END"})
P15=(-ssi_load_p0 694.4444444444445)          # 1000 N over the 1.44 m^2 cell
U=(-ssi_mesh grid -ssi_mesh_h 1.2 -ssi_mesh_patch 7.2,5.4 -ssi_load_group box:14.9,15.1,-0.1,0.1 "${P15[@]}"
   -ssi_lag_store toeplitz)
A=(-ssi_mesh grid -ssi_mesh_h 1.2 -ssi_mesh_patch 7.2,5.4 -ssi_load_group "" -ssi_load_area 14,15,-0.5,0.5
   -ssi_lag_store toeplitz)
X=(-ssi_interp none)
# the smooth load: p0 sin^2(pi t / T), T = 0.1 s, tabulated every 1 ms (linear between rows), zero after T
"$PY" -c "import numpy as np; t = np.r_[np.arange(0, 0.1005, 0.001), 10.0]; v = np.where(t <= 0.1, np.sin(np.pi * t / 0.1) ** 2, 0.0)
np.savetxt('$OUT/hann100ms.txt', np.c_[t, v], fmt='%.6g', header='t [s]  p / p0 [-]: a 0.1 s Hann pulse')"
S=(-ssi_load_history table -ssi_load_table "$OUT/hann100ms.txt")
run() { sampled_run "$@"; }
for r in $RUNS; do
  case $r in
    today) run today "${B[@]}" ;;
    today-load15) run today-load15 "${B[@]}" -ssi_mesh_params xl=15,w=1.2 "${P15[@]}" ;;
    # shellcheck disable=SC2086
    uniform-36) run uniform-36 "${B[@]}" "${U[@]}" -ssi_mesh_size 36,37.2 $EXTRA ;;
    # shellcheck disable=SC2086
    uniform-72) run uniform-72 "${B[@]}" "${U[@]}" -ssi_mesh_size 72,73.2 $EXTRA ;;
    # shellcheck disable=SC2086
    today-exact) run today-exact "${B[@]}" "${X[@]}" ;;
    today-fine) run today-fine "${B[@]}" "${X[@]}" -ssi_mesh_params g=1.15,hm=1.5,hr=1.0,hq=1.0 ;;
    today-smooth) run today-smooth "${B[@]}" "${X[@]}" "${S[@]}" ;;
    today-fine-smooth) run today-fine-smooth "${B[@]}" "${X[@]}" "${S[@]}" -ssi_mesh_params g=1.15,hm=1.5,hr=1.0,hq=1.0 ;;
    uniform-36-smooth) run uniform-36-smooth "${B[@]}" "${A[@]}" -ssi_mesh_size 36,37.2 "${X[@]}" "${S[@]}" ;;
    uniform-72-area-rule) run uniform-72-area-rule "${B[@]}" "${A[@]}" -ssi_mesh_size 72,73.2 -ssi_interp chebyshev \
                            -ssi_interp_tl 0.3675 -ssi_interp_k 27 ;;
    today-smooth-dt2) run today-smooth-dt2 "${B[@]}" "${X[@]}" "${S[@]}" -ssi_dt 2.5e-3 ;;
    uniform-36-smooth-dt2) run uniform-36-smooth-dt2 "${B[@]}" "${A[@]}" -ssi_mesh_size 36,37.2 "${X[@]}" "${S[@]}" \
                             -ssi_dt 2.5e-3 ;;
    today-load15-smooth) run today-load15-smooth "${B[@]}" -ssi_mesh_params xl=15,w=1.2 "${P15[@]}" "${X[@]}" "${S[@]}" ;;
    uniform-36-load15-smooth) run uniform-36-load15-smooth "${B[@]}" "${U[@]}" -ssi_mesh_size 36,37.2 "${X[@]}" "${S[@]}" ;;
    uniform-72-smooth) run uniform-72-smooth "${B[@]}" "${A[@]}" -ssi_mesh_size 72,73.2 "${X[@]}" "${S[@]}" ;;
    uniform-108-smooth) run uniform-108-smooth "${B[@]}" "${A[@]}" -ssi_mesh_size 108,109.2 "${X[@]}" "${S[@]}" ;;
    # shellcheck disable=SC2086
    uniform-72-area) run uniform-72-area "${B[@]}" "${A[@]}" -ssi_mesh_size 72,73.2 $EXTRA ;;
    # shellcheck disable=SC2086
    uniform-72-area-exact) run uniform-72-area-exact "${B[@]}" "${A[@]}" -ssi_mesh_size 72,73.2 "${X[@]}" $EXTRA ;;
    # shellcheck disable=SC2086
    uniform-36-area-exact) run uniform-36-area-exact "${B[@]}" "${A[@]}" -ssi_mesh_size 36,37.2 "${X[@]}" $EXTRA ;;
    uniform-72-fast) run uniform-72-fast "${B[@]}" "${U[@]}" -ssi_mesh_size 72,73.2 $FAST ;;
    uniform-72-fullrank) run uniform-72-fullrank "${B[@]}" "${U[@]}" -ssi_mesh_size 72,73.2 -ssi_step_blr 0 ;;
    uniform-72-blr) run uniform-72-blr "${B[@]}" "${U[@]}" -ssi_mesh_size 72,73.2 -ssi_bem_mat_mumps_icntl_35 2 \
                      -ssi_bem_mat_mumps_cntl_7 "$BLR_EPS" ;;
    # the exactness check on this case: uniform-36's first 6 steps (lags still block-sparse) dense and toeplitz
    check) run check-dense "${B[@]}" "${U[@]}" -ssi_mesh_size 36,37.2 -ssi_t_end 0.03 -ssi_lag_store dense
           run check-toeplitz "${B[@]}" "${U[@]}" -ssi_mesh_size 36,37.2 -ssi_t_end 0.03 ;;
    # petsc-ssi estimate of uniform-36 and uniform-72 (the cost model's prediction beside the runs; not runs)
    estimate) for size in 36,37.2 72,73.2; do
                "$PY" -m petsc_ssi estimate "${B[@]}" "${U[@]}" -ssi_mesh_size $size $EXTRA -ssi_estimate_ranks "$RANKS" \
                  > "$OUT/uniform-${size%%,*}.estimate" 2>&1 || true
              done ;;
    # petsc-ssi estimate of uniform-72-smooth and uniform-108-smooth (the toeplitz fit's building runs; not runs)
    estimate-smooth) for size in 72,73.2 108,109.2; do
                "$PY" -m petsc_ssi estimate "${B[@]}" "${A[@]}" -ssi_mesh_size $size "${X[@]}" "${S[@]}" \
                  -ssi_estimate_ranks "$RANKS" > "$OUT/uniform-${size%%,*}-smooth.estimate" 2>&1 || true
              done ;;
    *) echo "unknown run $r" >&2; exit 2 ;;
  esac
done
# the READMEs' tables and the CSVs from the default directory only (another OUT: printed)
tables_or_print out/bench/building_uniform jobscripts/building_uniform_table.py
