"""``petsc-ssi modes``: natural frequencies and mode shapes of a FE structure (SLEPc;
``fem.modes.compute_modes``)."""
import math

import numpy as np

from ..petsc import printf
from ..fem.modes import compute_modes, default_target, participation, modes_for, modal_participation_group


def main():
    """Collective: the ``petsc-ssi modes`` command (PETSc already initialised)."""
    from .static import structure_command
    PETSc, comm, cfg, model = structure_command("modes")
    target = PETSc.Options().getReal("ssi_modes_eps_target",
                                     default_target(model.material if model.material is not None else model,
                                                    model.mesh.coords))
    free = "free (6 rigid-body modes at 0 Hz)" if len(model.fixed) == 0 else "fixed: " + cfg.fem_fixed
    printf(f"[modes] {cfg.modes_n} lowest modes, {free}, shift-and-invert target {target:.4g} rad^2/s^2")
    freqs, shapes = compute_modes(model.K, model.m, model.fixed, cfg.modes_n, target)
    printf("mode,frequency_hz")
    for k, f in enumerate(freqs, 1):
        printf(f"{k},{f:.8g}")
    _damping_note(cfg, freqs)
    part = participation(shapes, model, comm)
    _participation_lines(part, freqs)
    if cfg.output:
        _write(cfg, model, freqs, shapes, comm, part)
    return freqs


# the log's effective heights are shown where the mode moves at least this share of the mass along the direction
# (the output file keeps every height, NaN where the mode has no share at all: fem.modes.participation)
HEIGHT_SHARE = 1e-4


def _participation_lines(p, freqs):
    """The log's table of effective modal masses (share of the total, cumulative) and heights."""
    b = p["base_point"]
    tot = p["total_mass"]
    printf(f"[modes] modal participation (shapes of the table above; base point ({b[0]:g}, {b[1]:g}, {b[2]:g}) m; "
           f"total mass moving with the base x {tot[0]:.6g} kg, y {tot[1]:.6g} kg, z {tot[2]:.6g} kg; a height "
           f"'-': the mode moves under {100 * HEIGHT_SHARE:g} % of the mass along that direction, a ratio of two "
           "near-zero sums); as CSV:")
    printf("mode,frequency_hz,meff_x_kg,meff_y_kg,meff_z_kg,ratio_x,ratio_y,ratio_z,cum_x,cum_y,cum_z,"
           "height_x_m,height_y_m")
    for k, f in enumerate(freqs):
        me, r, c, h = p["effective_mass"][k], p["effective_mass_ratio"][k], p["cumulative_mass_ratio"][k], \
            p["effective_height"][k]
        hs = ["-" if not np.isfinite(v) or not r[d] >= HEIGHT_SHARE else f"{v:.6g}" for d, v in enumerate(h)]
        printf(f"{k + 1},{f:.8g}," + ",".join(f"{v:.6g}" for v in me[:3]) + "," + ",".join(f"{v:.4f}" for v in r[:3])
               + "," + ",".join(f"{v:.4f}" for v in c[:3]) + "," + ",".join(hs))
    need = modes_for(p["cumulative_mass_ratio"])
    cum = p["cumulative_mass_ratio"][-1]
    printf("[modes] modes for 90 % of the mass: " + ", ".join(
        f"{d} {n}" if n else f"{d} not reached with {len(freqs)} ({100 * cum[i]:.1f} %; -ssi_modes_n more)"
        for i, (d, n) in enumerate(zip("xyz", need[:3]))))


def _damping_note(cfg, freqs):
    flex = freqs[freqs > 1e-6 * max(freqs.max(), 1e-300)]
    from ..fem.options import damping, rayleigh_zeta
    a0, a1, note = damping(cfg)
    if (a0 > 0 or a1 > 0) and flex.size:            # every mode's ratio of the damping a run would take
        printf(f"[modes] {note}: damping ratio of each flexible mode: "
               + ", ".join(f"{k + 1}: {float(z):.4g}" for k, z in
                           zip(range(len(freqs)), rayleigh_zeta(a0, a1, np.where(freqs > 0, freqs, np.inf)))
                           if freqs[k] in flex))
    from ..fem.modal_damping import ratios_of
    zm = ratios_of(cfg)
    if zm and flex.size:                            # -ssi_fem_modal_damping: its ratio in each damped mode
        printf("[modes] modal damping (-ssi_fem_modal_damping) of each flexible mode, added to the above: "
               + ", ".join(f"{k + 1}: {zm[i] if i < len(zm) else 0.0:.4g}"
                           for i, k in enumerate(k for k in range(len(freqs)) if freqs[k] in flex)))
    if cfg.fem_damping_ratio > 0 and flex.size:
        f1 = flex[0]
        printf(f"[modes] zeta = {cfg.fem_damping_ratio:g} at the first flexible mode f = {f1:.6g} Hz: "
               f"alpha_m = 2 zeta omega = {2 * cfg.fem_damping_ratio * 2 * math.pi * f1:.6g} 1/s "
               f"(with -ssi_fem_damping_freq {cfg.fem_damping_freq:g} Hz: "
               f"{2 * cfg.fem_damping_ratio * 2 * math.pi * cfg.fem_damping_freq:.6g} 1/s)")


def _write(cfg, model, freqs, shapes, comm, part=None):
    from ..io.output import Output, provenance
    from ..io.structure import FieldWriter
    out = Output(cfg.output, comm)
    fw = FieldWriter(out, model, comm)
    for k, s in enumerate(shapes, 1):
        fw.write(float(k), s, names=("mode_shape", "mode_shape_rotation", None))
    groups = {"modal_participation": modal_participation_group(part, freqs)} if part is not None and \
        comm.getRank() == 0 else None
    out.close(attrs={"problem": "modes", "frequencies_hz": np.asarray(freqs), "time_is": "mode number"},
              groups=groups,
              record=provenance(cfg, comm, {"modes": {"frequencies_hz": [float(f) for f in freqs]}}))
    printf(f"[modes] wrote {cfg.output} (+ .xmf, .json)")
