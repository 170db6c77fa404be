#!/usr/bin/env bash
# Weak scaling: the problem grows with the rank count p. The surface and the
# end time stay those of OPTIONS_FILE; the element size and the time step both
# shrink by sqrt(p) (h_p = H1/sqrt(p), dt_p = DT1/sqrt(p): the same
# beta = c dt / l), so the number of nodes grows about like p (the grid keeps
# the load patch edges, so it is not exactly p). Memory and work grow faster
# than p (N^2 x lags), so the weak efficiency is reported per unit of modelled
# work (jobscripts/scaling.py).
#   bash jobscripts/weak_scaling.sh OPTIONS_FILE [RANKS...]   (default ranks 1 2 4)
#   H1, DT1: element size and time step at 1 rank (default 1.0 m, 7.5e-4 s)
source "$(dirname "$0")/scaling_common.sh"
OPTS=${1:?usage: weak_scaling.sh OPTIONS_FILE [RANKS...]}
shift
RANKS=${*:-"1 2 4"}
H1=${H1:-1.0}
DT1=${DT1:-7.5e-4}
case=$(basename "$OPTS" .opts)
for n in $RANKS; do
  h=$("$PY" -c "print('%.6g' % ($H1 / $n ** 0.5))")
  dt=$("$PY" -c "print('%.6g' % ($DT1 / $n ** 0.5))")
  run_case "$OUT/weak-$case-n$n.log" "$n" weak "$case" \
    -options_file "$OPTS" -ssi_mesh_h "$h" -ssi_dt "$dt" -ssi_warn_beta 0 \
    -ssi_output "$OUT/weak-$case-n$n.h5" -ssi_output_stride 0
done
[ "${NO_REPORT:-0}" = 1 ] || "$PY" jobscripts/scaling.py "$OUT"
