#!/usr/bin/env bash
# A 28.8 m x 21.6 m building on a 72 m x 72 m site under an oblique SV wave (runs/seismic/site-oblique.opts;
# runs/seismic/README.md, "A large building on a large site, an oblique wave"): petsc-ssi estimate beside it, the
# run with -log_view -memory_view, the roof's response spectra (x and y), and site_oblique_report.py's tables.
#   bash runs/seismic/site_oblique.sh [NRANKS] [extra PETSc/-ssi_ options]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/../run_env.sh"      # (the repository root, PY, REC)
N=${1:-2}; shift || true
OUT=${OUT:-out/seismic}
mkdir -p "$OUT"
O=(-options_file runs/seismic/site-oblique.opts -ssi_seismic_record "$REC" -ssi_output "$OUT/site-oblique.h5")
"$PY" -m petsc_ssi estimate "${O[@]}" -ssi_estimate_ranks "$N" "$@" > "$OUT/site-oblique-n$N.estimate" 2>&1
# what the dense lag store would need (its model counts the blocks: about a minute)
"$PY" -m petsc_ssi estimate "${O[@]}" -ssi_lag_store dense -ssi_estimate_ranks "$N" "$@" \
  > "$OUT/site-oblique-dense-n$N.estimate" 2>&1 || true
mpirun --oversubscribe -n "$N" "$PY" -m petsc_ssi "${O[@]}" -ssi_output_overwrite -ssi_monitor \
  -log_view ":$OUT/site-oblique-n$N.log_view" -memory_view "$@" > "$OUT/site-oblique-n$N.log" 2>&1
cat "$OUT/site-oblique-n$N.log_view" >> "$OUT/site-oblique-n$N.log"
post() { "$PY" -m petsc_ssi post "$@" --overwrite; }
for c in x y; do     # the roof's centre (structure receiver 0), 5 % damping
  post "$OUT/site-oblique_structure.h5" --response-spectrum --receiver 0 --component $c --damping 0.05 \
    --csv "$OUT/site-oblique-roof-$c.csv" --png "$OUT/site-oblique-roof-$c.png"
done
"$PY" runs/seismic/site_oblique_report.py "$OUT" "$N"
