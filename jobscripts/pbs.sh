#!/bin/bash
# PBS (PBS Pro / OpenPBS / Torque) job script: a strong or weak scaling study of petsc_ssi.
#
#   qsub -l select=NODES:ncpus=CORES:mpiprocs=RANKS_PER_NODE -l walltime=HH:MM:SS \
#        -v STUDY=strong,OPTS=runs/pekeris/paper.opts,RANKS=8:16:32:64 jobscripts/pbs.sh
#   (Torque: -l nodes=NODES:ppn=RANKS_PER_NODE instead of select)
#
# Submit from the repository root. Nodes, ranks and time are qsub's own
# options (they override the #PBS defaults below); STUDY (strong|weak), the
# options file OPTS and the rank counts RANKS (separated by ':'; default: all
# ranks of the job) are passed with -v. The job runs
# jobscripts/<STUDY>_scaling.sh, the same driver as on a workstation, with
# mpiexec and the PBS node file, then jobscripts/scaling.py (CSV, plots,
# README table); fit this cluster's cost-model constants afterwards with
#   python jobscripts/calibrate.py --machine NAME --out NAME.json out/scaling/*.log
#PBS -N petsc-ssi-scaling
#PBS -l select=1:ncpus=4:mpiprocs=4
#PBS -l walltime=01:00:00
#PBS -j oe
# ---- site-specific environment: edit this block only -----------------------
# module load python petsc/3.18 openmpi
# export PY=$HOME/petsc_ssi/.venv/bin/python
# ----------------------------------------------------------------------------
set -euo pipefail
cd "${PBS_O_WORKDIR:-.}"
STUDY=${STUDY:-strong}
OPTS=${OPTS:?pass the options file: qsub -v OPTS=runs/...opts,STUDY=strong,RANKS=1:2:4 jobscripts/pbs.sh}
case "$STUDY" in strong|weak) ;; *) echo "STUDY must be strong or weak, not '$STUDY'" >&2; exit 2 ;; esac
NRANKS=$( [ -n "${PBS_NODEFILE:-}" ] && wc -l < "$PBS_NODEFILE" || echo 1)
NODES=$( [ -n "${PBS_NODEFILE:-}" ] && sort -u "$PBS_NODEFILE" | wc -l || echo 1)
RANKS=${RANKS:-$NRANKS}
RANKS=${RANKS//:/ }
export PBS_NUM_NODES=$NODES
export CORES=${CORES:-$(( NRANKS / NODES ))}
export MPIEXEC=${MPIEXEC:-mpiexec}
# At the walltime PBS sends SIGTERM, then SIGKILL after the queue's kill_delay; Open MPI's mpiexec,
# which gets the SIGTERM too, SIGKILLs the ranks 2 x this many seconds later (default 1 s: too
# short for petsc-ssi's output and checkpoint on a loaded node; README: "Signals under mpirun and
# schedulers"). PBS sends no signal ahead of the limit: use -ssi_checkpoint_interval, or
# `qsig -s USR1 JOBID` (mpiexec forwards SIGUSR1 to the ranks at once, without a kill).
export OMPI_MCA_odls_base_sigkill_timeout=${OMPI_MCA_odls_base_sigkill_timeout:-30}
if [ -n "${PBS_NODEFILE:-}" ] && [ -z "${MPIFLAGS:-}" ]; then
  MPIFLAGS="--hostfile $PBS_NODEFILE"        # Open MPI; MPICH/PBS-aware launchers: MPIFLAGS=" "
fi
export MPIFLAGS=${MPIFLAGS:-}
export OUT=${OUT:-out/scaling}
# shellcheck disable=SC2086
bash "jobscripts/${STUDY}_scaling.sh" "$OPTS" $RANKS
