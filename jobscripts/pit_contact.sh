#!/bin/bash
# Unilateral contact of a stiff block in a 2 x 2 x 1 m pit under a horizontal pulse pair (issue 42): counts
# the steps whose active set did not settle (-ssi_contact_separation free, the default: 48 of 56; auto: 0 of 56,
# runs/basement/README.md). Usage: bash jobscripts/pit_contact.sh [-ssi_contact_separation auto] [other options]
set -e
cd "$(dirname "$0")/.."
PY=${PY:-.venv/bin/python}
out=out/pit_contact; mkdir -p $out
$PY -c "import sys; sys.path.insert(0, 'runs/seismic'); import input_motion; input_motion.pulse('$out/pulse.txt', 0.04)"
$PY -m petsc_ssi run -ssi_problem ssi -ssi_mesh pit -ssi_mesh_params a=1,b=1,d=1 -ssi_mesh_size 6,6 -ssi_mesh_h 1 \
  -ssi_dt 0.0025 -ssi_t_end 0.14 -ssi_seismic vertical -ssi_seismic_record $out/pulse.txt -ssi_seismic_units m/s2 \
  -ssi_seismic_taper 0 -ssi_seismic_baseline none -ssi_fem_mesh box -ssi_fem_box_cells 4,4,3 \
  -ssi_fem_box_size 2,2,1.5 -ssi_fem_box_origin -1,-1,-1 -ssi_fem_interface xmin,xmax,ymin,ymax,base \
  -ssi_fem_E 3e10 -ssi_fem_nu 0.2 -ssi_fem_rho 2500 -ssi_contact unilateral -ssi_warn_beta 0 \
  -ssi_output $out/uni.h5 -ssi_output_overwrite 1 "$@" > $out/uni.log 2>&1
echo "steps that cycled: $(grep -c 'did not settle' $out/uni.log) of $(grep -o 'time loop: [0-9]* steps' $out/uni.log | grep -o '[0-9]*')"
