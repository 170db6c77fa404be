"""``petsc-ssi record FILE [-ssi_seismic_* options] [-ssi_record_csv OUT.csv]``: read and process an
earthquake record exactly as a run would (issue 43, item 7), without a model: the processing report
(format, units, samples, the processing, PGA/PGV/PGD, final velocity and displacement, Arias intensity,
D5-95 of the record as read and processed, the notes a run would print), the units' plausibility check
and the -ssi_seismic_target factor; with -ssi_record_csv the processed motion (every component: t,
acceleration, velocity, displacement, exactly integrated) as CSV with units in its header.

The processing options are the run's: -ssi_seismic_units, _format, _quantity, _component, _traces,
_scale, _window, _taper, _baseline, _highpass, _target, _target_damping, _units_check; FILE drives x
(one component, or the x, y, z columns of a 't ax ay az' table; -ssi_seismic_component picks another
axis). Serial work on rank 0; errors end with one line ``petsc-ssi: error: ...`` and status 2."""
import os

import numpy as np

from ..options import register
from ..petsc import SSIError, printf, warn

register("record_csv", "str", "", "", "petsc-ssi record: write the processed motion (axis, t [s], acceleration "
         "[m/s^2], velocity [m/s], displacement [m]) to this CSV ('-': standard output)", "seismic")


def main(argv):
    """Collective: the ``petsc-ssi record FILE`` command (PETSc initialised; ``argv``: the arguments after
    'record')."""
    from ..petsc import init
    from .. import options
    from ..seismic.input import collective_motions, record_lines
    PETSc = init()
    comm = PETSc.COMM_WORLD
    files = [a for i, a in enumerate(argv) if not a.startswith("-") and (i == 0 or not argv[i - 1].startswith("-"))]
    if len(files) != 1:
        raise SSIError("petsc-ssi record FILE: give one record file (then -ssi_seismic_* options)" if not files else
                       f"petsc-ssi record: one record file, got {len(files)}: {', '.join(files)}")
    path = files[0]
    if not os.path.isfile(path):
        raise SSIError(f"petsc-ssi record {path}: no such file")
    db = PETSc.Options()
    for opt in ("seismic", "seismic_record", "seismic_record_x", "seismic_record_y", "seismic_record_z"):
        if db.hasName("ssi_" + opt):          # before the options' own cross-checks
            raise SSIError(f"petsc-ssi record FILE takes the record as its argument: drop -ssi_{opt}")
    cfg = options.resolve(("common", "seismic"))
    csv = str(cfg.get("record_csv", "") or "")
    if csv and csv != "-":
        from .post import check_outputs, PostError
        try:
            check_outputs([("-ssi_record_csv", csv)], [path], bool(cfg.output_overwrite))
        except PostError as exc:
            raise SSIError(str(exc).replace("--overwrite", "-ssi_output_overwrite")) from None
    cfg.set("seismic", "vertical")
    cfg.set("seismic_record", path)
    cfg.set("dt", min(float(cfg.dt), 1e-9))       # no run: the record only needs to last one (tiny) step
    motions, notes = collective_motions(cfg, comm)
    for line in record_lines(motions, "[record]"):
        printf(line)
    for note in notes:
        warn(note, comm)
    if csv and comm.getRank() == 0:
        write_csv(csv, motions, path)
        if csv != "-":
            printf(f"[record] wrote {csv}")
    return motions


def write_csv(dest, motions, path):
    """Long format: axis, t [s], acceleration [m/s^2], velocity [m/s], displacement [m] per sample."""
    import sys
    fh = sys.stdout if dest == "-" else open(dest, "w")
    try:
        fh.write(f"# petsc-ssi record {os.path.abspath(path)}: the processed motion (exact integrals of the "
                 "piecewise-linear acceleration)\n")
        for axis, m in motions.items():
            p = m.processing
            fh.write(f"# {axis}: scale {p['scale']:.9g}" + (f"; {p['target']}" if p.get("target") else "") + "\n")
        fh.write("axis,t [s],acceleration [m/s^2],velocity [m/s],displacement [m]\n")
        for axis, m in motions.items():
            a, v, d = (np.asarray(x, float).reshape(len(m.t), -1)[:, 0] for x in (m.a, m.v, m.d))
            for row in zip(m.t, a, v, d):
                fh.write(axis + "," + ",".join(f"{x:.12g}" for x in row) + "\n")
    finally:
        if fh is not sys.stdout:
            fh.close()
