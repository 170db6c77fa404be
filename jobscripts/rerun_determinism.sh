#!/usr/bin/env bash
# Are reruns at -n 2 bitwise identical? Runs each case four times and prints max |a - b| / max |b|
# of the receivers (and of the interface series for the coupled case), then the exit status of a
# coupled run with both factorisations in SuperLU_dist. From the repository root, after make deps:
#   bash jobscripts/rerun_determinism.sh            (writes out/determinism/, ~3 minutes on 2 cores)
# The numbers in issue 14's note and tests/test_reproducible.py's docstring come from here.
set -u
cd "$(dirname "$0")/.."
PY=${PY:-.venv/bin/python}
OUT=out/determinism
mkdir -p "$OUT"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OPENBLAS_NUM_THREADS=1
FEM="-ssi_problem fem -ssi_fem_box_cells 2,2,2 -ssi_fem_fixed base -ssi_fem_load_group top -ssi_fem_load_p0 1000
     -ssi_dt 1e-3 -ssi_t_end 0.05 -ssi_receivers 0,0,0.5 -ssi_output_stride 0"
SSI="-ssi_problem ssi -ssi_cp 42 -ssi_cs 20 -ssi_rho 1800 -ssi_mesh_size 2,2 -ssi_mesh_h 0.5 -ssi_mesh_patch 0.5,0.5
     -ssi_fem_box_cells 4,4,1 -ssi_fem_box_size 1,1,0.25 -ssi_fem_box_origin -0.5,-0.5,0 -ssi_fem_E 300e9
     -ssi_fem_rho 200 -ssi_dt 0.0125 -ssi_t_end 0.5 -ssi_fem_load_group top -ssi_fem_load_p0 1000
     -ssi_fem_load_history box -ssi_fem_load_t0 0.05 -ssi_contact unilateral -ssi_receivers 1,0,0
     -ssi_output_stride 0 -ssi_warn_beta 0"
run() { local name=$1; shift; mpirun -n 2 "$PY" -m petsc_ssi "$@" -ssi_output "$OUT/$name.h5" -ssi_output_overwrite \
          > "$OUT/$name.log" 2>&1; echo "$name: exit $?"; }
# shellcheck disable=SC2086
{ for r in a b c d; do run fem-mumps-$r $FEM; run fem-repro-$r $FEM -ssi_reproducible; run ssi-mumps-$r $SSI
    run ssi-femslu-$r $SSI -ssi_fem_pc_factor_mat_solver_type superlu_dist; run ssi-repro-$r $SSI -ssi_reproducible; done
  run ssi-superlu-both $SSI -ssi_bem_pc_factor_mat_solver_type superlu_dist -ssi_fem_pc_factor_mat_solver_type superlu_dist
  run ssi-superlu-bem $SSI -ssi_bem_pc_factor_mat_solver_type superlu_dist
  run ssi-superlu-fem $SSI -ssi_fem_pc_factor_mat_solver_type superlu_dist; }
"$PY" - "$OUT" <<'PYEOF'
import sys, h5py, numpy as np
out = sys.argv[1]
def rel(a, b, key):
    with h5py.File(f"{out}/{a}.h5") as f, h5py.File(f"{out}/{b}.h5") as g:
        x, y = f[key][:], g[key][:]
    return float(np.abs(x - y).max() / max(np.abs(y).max(), 1e-300))
for case, keys in (("fem-mumps", ["receivers/u"]), ("fem-repro", ["receivers/u"]),
                   ("ssi-mumps", ["receivers/u", "interface/p", "interface/uf"]),
                   ("ssi-femslu", ["receivers/u", "interface/p", "interface/uf"]),
                   ("ssi-repro", ["receivers/u", "interface/p", "interface/uf"])):
    for r in "bcd":                          # rerun r against the first run
        print(f"{case} {r} vs a: " + ", ".join(f"{k} {rel(f'{case}-{r}', f'{case}-a', k):.2e}" for k in keys))
PYEOF
