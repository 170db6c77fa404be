#!/usr/bin/env bash
# The interface columns' region (coupling/columns.py) against its margin: the paper's building on the uniform
# 72 m grid (jobscripts/building_uniform.sh's uniform-72), one step, -ssi_interface_columns region with the
# margins MARGINS (in reaches of the step matrix, default "2 2.5 3 3.5 4 5"); per margin the region's DOFs and
# the truncation residual of the first margin tried (a margin whose residual is above 1e-14 is doubled: the
# log line's "tried first"), and the columns' seconds (SSI_Capacitance). A table on stdout.
#   bash jobscripts/columns_margin.sh
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
OUT=${OUT:-/tmp/columns_margin}
MARGINS=${MARGINS:-"2 2.5 3 3.5 4 5"}
RANKS=${RANKS:-2}
mkdir -p "$OUT"
echo "| margin [reaches] | margin [m] | region DOFs | truncation residual | margin kept [reaches] | interface matrices [s] |"
echo "|---|---|---|---|---|---|"
for m in $MARGINS; do
  mpirun --allow-run-as-root --oversubscribe -n "$RANKS" "$PY" -m petsc_ssi -options_file runs/building/ssi-full-bonded.opts \
    -ssi_mesh grid -ssi_mesh_h 1.2 -ssi_mesh_patch 7.2,5.4 -ssi_load_group box:14.9,15.1,-0.1,0.1 \
    -ssi_load_p0 694.4444444444445 -ssi_lag_store toeplitz -ssi_mesh_size 72,73.2 -ssi_t_end 0.005 \
    -ssi_interface_columns region -ssi_interface_columns_margin "$m" -ssi_output "$OUT/m$m.h5" \
    -ssi_output_overwrite -log_view > "$OUT/m$m.log" 2>&1
  "$PY" - "$OUT/m$m.log" "$m" <<'PYEOF'
import re, sys
text = open(sys.argv[1]).read()
line = [s for s in text.splitlines() if "interface columns: on the" in s][0]
n, margin, kept, reach = re.search(r"on the (\d+) soil DOFs within ([\d.]+) m .*margin ([\d.]+) x the step matrix's "
                                   r"reach ([\d.]+) m", line).groups()
first = re.search(r"tried first: ([\d.]+) m: residual ([\d.e+-]+)", line)
res = first.group(2) if first else re.search(r"truncation residual ([\d.e+-]+)", line).group(1)
m0 = float(sys.argv[2]) * float(reach)
cap = re.search(r"^SSI_Capacitance\s+\d+\s+\S+\s+(\S+)", text, re.M).group(1)
print(f"| {sys.argv[2]} | {m0:.3g} | {n if not first else '-'} | {res} | {kept} | {float(cap):.3g} |")
PYEOF
done
