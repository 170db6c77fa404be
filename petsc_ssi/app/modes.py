"""``petsc-ssi modes``: natural frequencies and mode shapes of a FE structure (SLEPc;
``fem.modes.compute_modes``)."""
import math

import numpy as np

from ..petsc import printf
from ..fem.modes import compute_modes, default_target


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
    if cfg.output:
        _write(cfg, model, freqs, shapes, comm)
    return freqs


def _damping_note(cfg, freqs):
    flex = freqs[freqs > 1e-6 * max(freqs.max(), 1e-300)]
    from ..fem.options import damping, rayleigh_zeta
    a0, a1, note = damping(cfg)
    if (a0 > 0 or a1 > 0) and flex.size:            # every mode's ratio of the damping a run would take
        printf(f"[modes] {note}: damping ratio of each flexible mode: "
               + ", ".join(f"{k + 1}: {float(z):.4g}" for k, z in
                           zip(range(len(freqs)), rayleigh_zeta(a0, a1, np.where(freqs > 0, freqs, np.inf)))
                           if freqs[k] in flex))
    if cfg.fem_damping_ratio > 0 and flex.size:
        f1 = flex[0]
        printf(f"[modes] zeta = {cfg.fem_damping_ratio:g} at the first flexible mode f = {f1:.6g} Hz: "
               f"alpha_m = 2 zeta omega = {2 * cfg.fem_damping_ratio * 2 * math.pi * f1:.6g} 1/s "
               f"(with -ssi_fem_damping_freq {cfg.fem_damping_freq:g} Hz: "
               f"{2 * cfg.fem_damping_ratio * 2 * math.pi * cfg.fem_damping_freq:.6g} 1/s)")


def _write(cfg, model, freqs, shapes, comm):
    from ..io.output import Output, provenance
    from ..io.structure import FieldWriter
    out = Output(cfg.output, comm)
    fw = FieldWriter(out, model, comm)
    for k, s in enumerate(shapes, 1):
        fw.write(float(k), s, names=("mode_shape", "mode_shape_rotation", None))
    out.close(attrs={"problem": "modes", "frequencies_hz": np.asarray(freqs), "time_is": "mode number"},
              record=provenance(cfg, comm, {"modes": {"frequencies_hz": [float(f) for f in freqs]}}))
    printf(f"[modes] wrote {cfg.output} (+ .xmf, .json)")
