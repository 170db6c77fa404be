#!/usr/bin/env bash
# Benchmark of the toeplitz lag store (issue 41; petsc_ssi/bem/toeplitz.py) against the dense lag
# matrices, on RANKS ranks (default 2), with -log_view and -memory_view:
#   - the paper's Lamb case as it is (quarter model: runs/pekeris/paper.opts), dense and toeplitz;
#   - the paper's case meshed whole (-ssi_symmetry none): dense (refused on a 24 GB node: its log
#     keeps the refusal) and toeplitz; its receivers against the quarter model's;
#   - whole grids of SIZES metres (1 m elements, the paper's soil and dt, T_END seconds): the cost per
#     step against N, and the run's own estimate beside each.
#   - the paper's whole case at 1, 2 and 4 ranks (SCALE_RANKS): the scaling table.
#   - sites of SITE_SIZES metres (1 m elements, no symmetry, 0.3 s: issue 41's 100 m site and a sweep)
#     with the far lags interpolated (SITE_INTERP: multi-linear from T_L = 1.5 r / c_s at the 15 m
#     receiver, one matrix every 10 steps), each with `petsc-ssi estimate` beside it; the smallest also
#     exact (all lags), for what the interpolation does to the receivers.
# Then jobscripts/toeplitz_table.py writes the table into runs/pekeris/README.md, the CSV
# runs/pekeris/toeplitz_bench.csv, the plot runs/pekeris/toeplitz_cost_per_step.png and the scaling
# table into jobscripts/README.md.
#   bash jobscripts/toeplitz_bench.sh            (RANKS=1 SIZES="24 36" T_END=0.05 to change;
#   PARTS="site" runs only the sites; PARTS="paper grid scale site" is everything; SITE_OPTS: options of
#   every site run, default single-precision kept transforms; SITE_EXACT: the size whose all-exact sibling
#   runs, default the first of SITE_SIZES, "" none; MIN_FREE_GB: stop a run when the machine's available
#   memory falls below this many GB, default 0: never. Every run's log ends with its ranks' resident
#   memory sampled every 2 s: "# sampled peak RSS over the ranks")
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
RANKS=${RANKS:-2}
SIZES=${SIZES:-"24 36 48 64"}
T_END=${T_END:-0.06}
OUT=${OUT:-out/bench/toeplitz}
PARTS=${PARTS:-"paper grid scale site"}
SITE_SIZES=${SITE_SIZES:-"40 50 60 80 100"}
SITE_INTERP=${SITE_INTERP:-"-ssi_interp linear -ssi_interp_tl 0.0712 -ssi_interp_k 31"}
SITE_OPTS=${SITE_OPTS:-"-ssi_toeplitz_precision single"}
SITE_EXACT=${SITE_EXACT-${SITE_SIZES%% *}}
MIN_FREE_GB=${MIN_FREE_GB:-0}
has() { [[ " $PARTS " == *" $1 "* ]]; }
mkdir -p "$OUT"
"$PY" -m petsc_ssi.app.warmup > /dev/null
run() { sampled_run "$@"; }
P=(-options_file runs/pekeris/paper.opts)
if has paper; then
  run paper-quarter-dense "${P[@]}"
  run paper-quarter-toeplitz "${P[@]}" -ssi_lag_store toeplitz
  run paper-whole-dense "${P[@]}" -ssi_symmetry none
  run paper-whole-toeplitz "${P[@]}" -ssi_symmetry none -ssi_lag_store toeplitz
fi
if has grid; then
  for L in $SIZES; do
    run "grid-$L" "${P[@]}" -ssi_symmetry none -ssi_lag_store toeplitz -ssi_mesh_size "$L,$L" -ssi_t_end "$T_END" \
      -ssi_receivers "5,0,0"
  done
fi
# scaling of the paper's whole case at SCALE_RANKS ranks (4 oversubscribed on a 2-core machine)
if has scale; then
  R0=$RANKS
  for n in ${SCALE_RANKS:-1 2 4}; do
    RANKS=$n run "scale-n$n" "${P[@]}" -ssi_symmetry none -ssi_lag_store toeplitz
  done
  RANKS=$R0
fi
# the sites (issue 41's 100 m item): interpolated far lags, the estimate of each beside it
if has site; then
  # shellcheck disable=SC2206
  S=("${P[@]}" -ssi_symmetry none -ssi_lag_store toeplitz -ssi_t_end 0.3 $SITE_OPTS)
  if [[ -n "$SITE_EXACT" ]]; then
    run "site-$SITE_EXACT-exact" "${S[@]}" -ssi_mesh_size "$SITE_EXACT,$SITE_EXACT"
  fi
  for L in $SITE_SIZES; do
    # shellcheck disable=SC2086
    run "site-$L" "${S[@]}" -ssi_mesh_size "$L,$L" $SITE_INTERP
  done
  for L in $SITE_SIZES; do
    # shellcheck disable=SC2086
    "$PY" -m petsc_ssi estimate "${S[@]}" -ssi_mesh_size "$L,$L" $SITE_INTERP -ssi_estimate_ranks "$RANKS" \
      > "$OUT/site-$L.estimate" 2>&1 || true
  done
fi
# the repository's tables, CSVs and plots from the default OUT only; another OUT's are printed (its CSV and plots there)
if [[ "$OUT" == out/bench/toeplitz ]]; then
  "$PY" jobscripts/toeplitz_table.py "$OUT" runs/pekeris/README.md runs/pekeris/toeplitz_bench.csv \
    runs/pekeris/toeplitz_cost_per_step.png jobscripts/README.md
else
  "$PY" jobscripts/toeplitz_table.py "$OUT" --print
fi
