"""``petsc-ssi input-motion``: the foundation input motion of a rigid massless surface footing under a
seismic wave (kinematic interaction; issue 27), beside ``petsc-ssi impedance``; also of an embedded one,
the walls and bottom of an excavation (``-ssi_mesh pit -ssi_disp_group pit``; runs/embedment/input_motion.py).

The footing is the -ssi_disp_group region (a group or 'box:x0,x1,y0,y1'), the wave -ssi_seismic with
its record (-ssi_seismic_record ...). One BEM run (-ssi_problem bem with -ssi_disp_rigid massless,
``bem/input_motion.py``) finds each step the footing's rigid motion q = (u_x, u_y, u_z, theta_x,
theta_y, theta_z) about -ssi_disp_ref (default: the region's centroid) that makes the soil's
resultant force and moment on it zero. Under vertical incidence q is the free field (no kinematic
interaction); an oblique or Rayleigh wave rotates the footing (torsion, rocking) and filters its
translation at short wavelengths (base-slab averaging); at long periods q tends to the free field at
x_ref and its rotation, 1/2 curl u_ff. The run refuses to start without a wave or without a region;
symmetry planes (-ssi_symmetry) are taken where the wave allows them (a wave may travel along a plane,
not across it) and reduce the unknown modes to those the planes allow.

Outputs, from -ssi_output's stem (default out/input-motion.h5):
  <stem>.h5                the run, with the group input_motion: translation [m], rotation [rad],
                           acceleration [m/s^2], angular_acceleration [rad/s^2] of the footing per
                           step, free_field_* the same of the free field at x_ref, x_ref, modes,
                           step_stiffness (units as attributes); resultants (F, M ~ 0: the condition)
  <stem>-input-motion.csv  one row per step: t [s], the footing's and the free field's translations,
                           rotations and their accelerations (units in the column names)
  <stem>-input-motion.png  time histories, footing against free field, per component
and prints per component the peak of the footing's motion and acceleration against the free field's.
"""
import os

import numpy as np

from ..petsc import init, SSIError, printf

COMPONENTS = (("u_x", "m"), ("u_y", "m"), ("u_z", "m"), ("theta_x", "rad"), ("theta_y", "rad"), ("theta_z", "rad"))


def columns(g):
    """(header, table (K, 25)) of the CSV from the output group ``g`` ({name: (array, unit)})."""
    t = g["t"][0]
    motion = np.c_[g["translation"][0], g["rotation"][0]]
    acc = np.c_[g["acceleration"][0], g["angular_acceleration"][0]]
    ff = np.c_[g["free_field_translation"][0], g["free_field_rotation"][0]]
    ffa = np.c_[g["free_field_acceleration"][0], g["free_field_angular_acceleration"][0]]
    head = ["t_s"]
    for pre, acc_ in (("", False), ("", True), ("ff_", False), ("ff_", True)):
        for name, unit in COMPONENTS:
            head.append(f"{pre}{'a_' if acc_ else ''}{name}_{unit}{'_s2' if acc_ else ''}")
    return head, np.c_[t, motion, acc, ff, ffa]


def write_csv(path, g):
    head, table = columns(g)
    np.savetxt(path, table, delimiter=",", header=",".join(head), comments="", fmt="%.10g")


def peaks(g):
    """[(component, peak footing, peak free field, ratio, peak footing accel., peak free-field accel.,
    ratio)] of the unknown modes."""
    motion = np.c_[g["translation"][0], g["rotation"][0]]
    acc = np.c_[g["acceleration"][0], g["angular_acceleration"][0]]
    ff = np.c_[g["free_field_translation"][0], g["free_field_rotation"][0]]
    ffa = np.c_[g["free_field_acceleration"][0], g["free_field_angular_acceleration"][0]]
    out = []
    for k in np.asarray(g["modes"][0]):
        pm, pf, am, af = (float(np.abs(v[:, k]).max()) for v in (motion, ff, acc, ffa))
        out.append((COMPONENTS[k][0], pm, pf, pm / pf if pf else np.nan, am, af, am / af if af else np.nan))
    return out


def residual(g, resultants):
    """(force, moment): max |F| and max |M| of the run's resultants over the largest force and moment
    W q of the footing's motion q through its step stiffness W (0 when the condition holds)."""
    W = g["step_stiffness"][0]
    q = np.c_[g["translation"][0], g["rotation"][0]]
    wq = q @ W.T
    fm = np.c_[resultants["force"], resultants["moment"]]
    out = []
    for rows in (slice(0, 3), slice(3, 6)):
        scale = np.abs(wq[:, rows]).max()
        out.append(float(np.abs(fm[:, rows]).max() / scale) if scale > 0 else 0.0)
    return tuple(out)


def plot(path, g):
    """Time histories, footing (solid) against the free field at x_ref (dashed): translations,
    rotations and their accelerations; a panel whose values are all below 1e-9 of its row's largest
    is marked '~ 0' (round-off: a component the wave does not excite)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t = g["t"][0]
    rows = [("translation", "free_field_translation", "m", ("u_x", "u_y", "u_z")),
            ("rotation", "free_field_rotation", "rad", ("theta_x", "theta_y", "theta_z")),
            ("acceleration", "free_field_acceleration", "m/s^2", ("a_x", "a_y", "a_z")),
            ("angular_acceleration", "free_field_angular_acceleration", "rad/s^2", ("alpha_x", "alpha_y", "alpha_z"))]
    fig, axes = plt.subplots(4, 3, figsize=(13, 11), sharex=True)
    for (key, ffkey, unit, names), row in zip(rows, axes):
        v, f = g[key][0], g[ffkey][0]
        big = max(np.abs(v).max(), np.abs(f).max(), 1e-300)
        for k, ax in enumerate(row):
            ax.plot(t, f[:, k], "k--", lw=1.0, label="free field at x_ref")
            ax.plot(t, v[:, k], "C0", lw=1.3, label="massless footing")
            tiny = max(np.abs(v[:, k]).max(), np.abs(f[:, k]).max()) < 1e-9 * big
            ax.set_title(names[k] + (" (~ 0)" if tiny else ""), fontsize=9)
            ax.set_ylabel(f"{names[k]} [{unit}]")
    for ax in axes[-1]:
        ax.set_xlabel("t [s]")
    axes[0, 0].legend(fontsize=8)
    x = g["x_ref"][0]
    fig.suptitle(f"foundation input motion about x_ref = ({x[0]:.4g}, {x[1]:.4g}, {x[2]:.4g}) m (translations of "
                 "x_ref, small rotations about it; accelerations: second differences)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main():
    """Collective: the ``petsc-ssi input-motion`` command (PETSc already initialised)."""
    PETSc = init()
    comm = PETSc.COMM_WORLD
    from .. import options
    from ..bem.problem import BEMTransient
    db = PETSc.Options()
    kind = db.getString("ssi_problem", "bem").strip().lower()
    if kind != "bem":
        raise SSIError(f"petsc-ssi input-motion runs the half-space alone; drop -ssi_problem {kind}")
    rigid = db.getString("ssi_disp_rigid", "massless").strip().lower()
    if rigid != "massless":
        raise SSIError(f"petsc-ssi input-motion finds a massless footing's motion; drop -ssi_disp_rigid {rigid}")
    if db.getString("ssi_seismic", "none").strip().lower() == "none":
        raise SSIError("petsc-ssi input-motion needs a seismic input: -ssi_seismic vertical|sh|sv|p|rayleigh with "
                       "its record (-ssi_seismic_record FILE)")
    if not db.getString("ssi_disp_group", "").strip():
        raise SSIError("petsc-ssi input-motion needs the footing as -ssi_disp_group (a group or 'box:x0,x1,y0,y1')")
    db.setValue("ssi_disp_rigid", "massless")
    if db.hasName("ssi_output") and not (db.getString("ssi_output", "") or "").strip():
        raise SSIError("-ssi_output '': petsc-ssi input-motion keeps its results in files (<stem>.h5, "
                       "<stem>-input-motion.csv and .png); give -ssi_output FILE.h5, or leave it out for "
                       "out/input-motion.h5")
    if not db.getString("ssi_output", "").strip():
        db.setValue("ssi_output", "out/input-motion.h5")
    cfg = options.resolve(("common", "bem", "seismic"))
    from ..io.output import replace_error
    from ..petsc import collective_error
    stem = os.path.splitext(cfg.output)[0]
    err = None
    for f in (stem + "-input-motion.csv", stem + "-input-motion.png"):
        err = err or replace_error(f, f"-ssi_output {cfg.output}", overwrite=bool(cfg.get("output_overwrite")))
    collective_error(err, comm)              # before the run: the user's files are never replaced unasked
    res = BEMTransient(cfg, comm).run()
    if comm.getRank() == 0:
        g = res["input_motion"]
        stem = os.path.splitext(cfg.output)[0]
        write_csv(stem + "-input-motion.csv", g)
        plot(stem + "-input-motion.png", g)
        rel_f, rel_m = residual(g, res["resultants"])
        printf("[input-motion] peaks, footing against the free field at x_ref (motion; acceleration):")
        for name, pm, pf, ratio, am, af, aratio in peaks(g):
            unit = dict(COMPONENTS)[name]
            if pf > 0:
                printf(f"[input-motion]   {name}: {pm:.5g} / {pf:.5g} {unit} = {ratio:.4g}; {am:.5g} / {af:.5g} "
                       f"{unit}/s^2 = {aratio:.4g}")
            else:
                printf(f"[input-motion]   {name}: {pm:.5g} {unit}, {am:.5g} {unit}/s^2 (the free field's is 0)")
        printf(f"[input-motion] resultant on the footing (the zero-resultant condition): force at most {rel_f:.2g}, "
               f"moment at most {rel_m:.2g} of the largest step-stiffness force and moment of its motion")
        printf(f"[input-motion] wrote {stem}-input-motion.csv and {stem}-input-motion.png")
    comm.tompi4py().Barrier()
