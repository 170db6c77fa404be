"""Options of the structural FEM (group "fem"), declared once in the registry.

Units are SI; z is up. ``-ssi_fem_ksp_*`` / ``-ssi_fem_pc_*`` go to the PETSc
solver of D (paper eq. 15) and ``-ssi_modes_eps_*`` / ``-ssi_modes_st_*`` to
SLEPc, unchanged (they are PETSc object options, not registry entries).
"""
import os

from ..options import register, register_check, positive, nonnegative, at_least
from ..petsc import SSIError
from ..points import parse_triple
from .. import common_options  # noqa: F401  (the common options every problem reads)
from . import parts as _parts  # noqa: F401  (-help lists the per-part options)
from ..seismic import options as _seismic_options  # noqa: F401  (a fixed base moving with a record)
from . import demands as _demands  # noqa: F401  (-ssi_structure_drift_*: the storey demands' options)

G = "fem"


def _nu_range(v):
    return None if -1.0 < v < 0.5 else "Poisson's ratio must lie in (-1, 0.5)"


def parse_pair(text):
    """'a,b' -> (a, b) floats; SSIError otherwise."""
    try:
        vals = [float(x) for x in str(text).replace(";", ",").split(",") if x.strip()]
    except ValueError:
        vals = []
    if len(vals) != 2:
        raise SSIError("expected two comma-separated numbers")
    return vals[0], vals[1]


def _pair(what, nonneg=False, positive=False):
    def check(text):
        if not str(text).strip():
            return None
        try:
            a, b = parse_pair(text)
        except SSIError:
            return f"must be two comma-separated numbers '{what}'"
        import math
        if not (math.isfinite(a) and math.isfinite(b)):
            return f"must be two finite numbers '{what}'"
        if nonneg and min(a, b) < 0:
            return f"'{what}' must be >= 0 (a negative value is negative damping)"
        if positive and min(a, b) <= 0:
            return f"'{what}' must be > 0"
        return None
    return check


def _triple(kind):
    def check(text):
        try:
            parse_triple(text, kind)
        except SSIError:
            return "must be three comma-separated numbers"
        return None
    return check


register("fem_mesh", "str", "box", "",
         "mesh of the structure: 'box' (structured hex8 generator, see -ssi_fem_box_*) "
         "or a gmsh .geo/.msh file (hex8, quad4 shells, line2 frames; paths relative to the working directory)", G)
register("fem_mesh_params", "str", "", "", "parameters of a .geo structure mesh 'name=value,...' (gmsh ONELAB "
         "'Parameters/name', e.g. DefineConstant[ nbx = {4, Name \"Parameters/nbx\"} ])", G)
register("fem_parts", "str", "", "", "parts of the structure: physical groups that carry elements, 'NAME,...', each "
         "with -ssi_fem_part_NAME_element hex8|frame|shell and its properties (petsc-ssi help lists them); "
         "empty: one hex8 part of every brick with -ssi_fem_E/_nu/_rho", G)
register("fem_box_cells", "str", "10,10,4", "cells", "box: number of bricks 'nx,ny,nz'", G,
         validator=_triple(int))
register("fem_box_size", "str", "1,1,0.5", "m", "box: edge lengths 'lx,ly,lz'", G, validator=_triple(float))
register("fem_box_origin", "str", "-0.5,-0.5,0", "m", "box: lowest corner 'x0,y0,z0' (default: paper block "
         "centred at x=y=0, base z=0)", G, validator=_triple(float))
register("fem_renumber", "bool", True, "", "reverse Cuthill-McKee node renumbering (compact rank partitions)", G)
register("fem_E", "real", 300e6, "N/m^2", "Young's modulus of the structure (paper: concrete 300e6)", G,
         validator=positive)
register("fem_nu", "real", 0.2, "", "Poisson's ratio of the structure, in (-1, 0.5)", G, validator=_nu_range)
register("fem_rho", "real", 2000.0, "kg/m^3", "density of the structure (lumped mass)", G, validator=positive)
register("fem_cp", "real", 0.0, "m/s", "P-wave speed of the structure's single hex8 part, with -ssi_fem_cs and "
         "-ssi_fem_rho (required with them) instead of -ssi_fem_E and -ssi_fem_nu (a soil region filling an excavation); "
         "0: unused", G,
         validator=nonnegative)
register("fem_cs", "real", 0.0, "m/s", "S-wave speed of the structure's single hex8 part (with -ssi_fem_cp)", G,
         validator=nonnegative)
register("fem_alpha_m", "real", 0.0, "1/s", "mass-proportional damping C = alpha_m M", G, validator=nonnegative)
register("fem_damping_ratio", "real", 0.0, "", "damping ratio zeta at -ssi_fem_damping_freq: alpha_m = 2 zeta "
         "omega (instead of -ssi_fem_alpha_m)", G, validator=nonnegative)
register("fem_damping_freq", "real", 0.0, "Hz", "reference frequency of -ssi_fem_damping_ratio", G,
         validator=nonnegative)
register("fem_rayleigh", "str", "", "1/s, s", "Rayleigh damping C = a0 M + a1 K by its coefficients 'a0,a1' "
         "(zeta(f) = a0/(2 omega) + a1 omega/2, omega = 2 pi f); instead of -ssi_fem_alpha_m, "
         "-ssi_fem_damping_ratio and -ssi_fem_rayleigh_freqs", G, validator=_pair("a0,a1", nonneg=True))
register("fem_rayleigh_freqs", "str", "", "Hz", "Rayleigh damping C = a0 M + a1 K from two frequencies 'f1,f2' "
         "(f1 < f2) and the ratios -ssi_fem_rayleigh_ratios there: a0 = 2 w1 w2 (z1 w2 - z2 w1)/(w2^2 - w1^2), "
         "a1 = 2 (z2 w2 - z1 w1)/(w2^2 - w1^2); between them zeta is below the targets, outside above",
         G, validator=_pair("f1,f2", positive=True))
register("fem_rayleigh_ratios", "str", "", "1", "damping ratios 'z1,z2' at -ssi_fem_rayleigh_freqs (e.g. "
         "0.05,0.05)", G, validator=_pair("z1,z2", nonneg=True))
register("fem_modal_damping", "str", "", "1", "modal damping: one ratio 'z' for each of the first "
         "-ssi_fem_modal_modes flexible modes, or one ratio per mode 'z1,z2,...' (0.05: 5 % of critical); "
         "C = alpha_m M + a1 K + sum_i 2 z_i omega_i (M phi_i)(M phi_i)^T over the structure's modes on its supports "
         "(rigid-body modes left out), added to any Rayleigh damping; the modes above get none from it", G)
register("fem_modal_modes", "int", 0, "", "number of flexible modes -ssi_fem_modal_damping damps with its one ratio "
         "(0: 10)", G, validator=nonnegative)
register("fem_integrator", "enum", "green", "", "time integrator: green (implicit Green's functions, paper "
         "eqs. 13-24) or newmark (plain Newmark)", G, choices=("green", "newmark"))
register("fem_newmark_alpha", "real", 0.25, "", "Newmark alpha (beta in most texts); green needs "
         "delta^2 = alpha", G, validator=positive)
register("fem_newmark_delta", "real", 0.5, "", "Newmark delta (gamma in most texts)", G, validator=positive)
register("fem_solver", "enum", "direct", "", "solver of D: direct (factorise once, MUMPS) or iterative "
         "(CG + hypre BoomerAMG); -ssi_fem_ksp_*/-ssi_fem_pc_* override", G, choices=("direct", "iterative"))
register("fem_load_group", "str", "", "", "loaded faces: comma-separated groups of brick faces or shell cells, "
         "each with an optional factor on p0 (e.g. top, or top_left,top_right:-1)", G)
register("fem_load_p0", "real", 0.0, "N/m^2", "pressure on the load group; p0 > 0 pushes into the body "
         "(traction -p0 h(t) n, n the outward normal; on shells, cells oriented up: pushes a slab down)", G)
register("fem_load_history", "enum", "heaviside", "", "load history h(t) of the pressure and point loads: "
         "heaviside (1 for t > 0), box (1 on (0, t0]), table, smoothstep ((1 - cos(pi t/t0))/2 up to t0, then 1)", G,
         choices=("heaviside", "box", "table", "smoothstep"))
register("fem_load_t0", "real", 0.025, "s", "duration of the box pulse, rise time of the smoothstep", G,
         validator=positive)
register("fem_load_table", "str", "", "", "file of 't h' rows, h linearly interpolated (0 before the first "
         "time, the last value after the last)", G)
register("fem_point_load", "str", "", "m, N, N m", "point loads 'x,y,z,fx,fy,fz[,mx,my,mz];...' at the nearest "
         "FE node, or 'GROUP,fx,fy,fz[,mx,my,mz]' on every node of a group, times h(t) (moments need frame or "
         "shell nodes)", G)
register("fem_point_mass", "str", "", "m, kg, kg m^2", "added point masses 'x,y,z,m[,I];...' at the nearest "
         "FE node or 'GROUP,m[,I]' on every node of a group: m on the translations, I (default 0) on the "
         "rotations of frame/shell nodes", G)
register("fem_fixed", "str", "", "", "fixed dofs by node group 'group[:dofs],...': a bare group fixes all its dofs, "
         "dof names ux uy uz rx ry rz joined by '+' (e.g. 'base,symx:ux+ry+rz,pin:uz'), letters of xyz fix "
         "translations ('xmin:x')", G)
register("structure_forces", "str", "", "", "member forces of frame and shell parts: 'PART,...' or 'all' (every "
         "frame and shell part; '' or none: no forces): frame end forces (N, V2, V3, T, M2, M3 at both ends, local "
         "axes) and shell stress resultants (N11, N22, N12, M11, M22, M12, Q1, Q2 at the centre, local frame) with "
         "every structure snapshot, their peak over all steps, and the peaks as XDMF cell fields "
         "(petsc_ssi/fem/forces.py)", G)
# -ssi_fem_gravity: the self-weight as a static case (fem/gravity.py)
G_MAX = 100.0                 # m/s^2: above it the value is taken for cm/s^2 or a typo

def _gravity_ok(v):
    if not v >= 0:
        return "must be >= 0 m/s^2 (the acceleration of gravity, acting along -z; 0: no gravity case)"
    if v > G_MAX:
        return (f"{v:g} m/s^2 is not a gravity in m/s^2 (9.81 on Earth; {v:g} looks like cm/s^2); "
                f"give it in m/s^2, at most {G_MAX:g}")
    return None


register("fem_gravity", "real", 0.0, "m/s^2", "gravity g acting along -z: the structure's self-weight (its lumped "
         "masses: elements, added and point masses) as a static case solved once (fixed base and petsc-ssi static); "
         "its member forces and support reactions are written beside the earthquake's, with the combined envelopes "
         "G + max E and G + min E (petsc_ssi/fem/gravity.py); 0: none", G, validator=_gravity_ok)


def _coupled_check(cfg):
    if cfg.get("problem", "fem") == "ssi" and float(cfg.get("fem_gravity", 0.0) or 0.0) > 0:
        return ("-ssi_fem_gravity is built for the fixed base (-ssi_problem fem) and petsc-ssi static: the soil's "
                "static response to the weight is not modelled in a coupled run; leave it out there "
                "(-ssi_contact_preload weight gives the weight's contact pressure)")
    return None


register_check(("fem", "ssi"), _coupled_check)


register("modes_n", "int", 6, "", "petsc-ssi modes: number of natural modes", G, validator=at_least(1))


def _fem_checks(cfg):
    if cfg.t_end < cfg.dt:
        return f"-ssi_t_end {cfg.t_end} is shorter than one step -ssi_dt {cfg.dt}"
    if cfg.fem_mesh != "box" and not os.path.isfile(cfg.fem_mesh):
        return f"-ssi_fem_mesh {cfg.fem_mesh}: no such file (relative to {os.getcwd()})"
    if cfg.user_set("fem_alpha_m") and cfg.fem_damping_ratio > 0:
        return "give either -ssi_fem_alpha_m or -ssi_fem_damping_ratio, not both"
    msg = _rayleigh_check(cfg)
    if msg:
        return msg
    from .modal_damping import check_options
    msg = check_options(cfg)
    if msg:
        return msg
    if cfg.fem_damping_ratio > 0 and cfg.fem_damping_freq <= 0:
        return "-ssi_fem_damping_ratio needs a reference frequency -ssi_fem_damping_freq > 0"
    if cfg.fem_load_p0 != 0 and not cfg.fem_load_group.strip():
        return "-ssi_fem_load_p0 is set but -ssi_fem_load_group names no face group"
    from .loads import uses_history, history_from
    if uses_history(cfg) and cfg.fem_load_history == "table" and not os.path.isfile(cfg.fem_load_table):
        return f"-ssi_fem_load_table '{cfg.fem_load_table}': no such file"
    if uses_history(cfg):                     # read and check the table now, before any assembly
        try:
            history_from(cfg)
        except SSIError as exc:
            return f"-ssi_fem_load_history {cfg.fem_load_history}: {exc}"
    a, d = cfg.fem_newmark_alpha, cfg.fem_newmark_delta
    if cfg.fem_integrator == "green" and abs(d * d - a) > 1e-12:
        return (f"-ssi_fem_integrator green needs delta^2 = alpha (paper eq. 24); got "
                f"alpha {a}, delta {d}")
    if d < 0.5 or a < d / 2:
        return f"Newmark alpha {a}, delta {d} is not unconditionally stable (need delta >= 1/2, alpha >= delta/2)"
    return None


register_check((G,), _fem_checks)


def _forces_check(cfg):
    """-ssi_structure_forces names frame and shell parts (checked before any mesh is read)."""
    text = str(cfg.get("structure_forces", "") or "").strip()
    if not text or text == "none":
        return None
    from .parts import parse_parts
    from .forces import parse_force_parts
    try:
        specs = parse_parts(cfg)
    except SSIError:
        return None                  # the parts' own error comes with the model
    try:
        parse_force_parts(text, specs)
    except SSIError as exc:
        return str(exc)
    return None


register_check((G,), _forces_check)


def rayleigh_from_ratios(f1, f2, z1, z2):
    """(a0 [1/s], a1 [s]) of C = a0 M + a1 K with damping ratios z1 at f1 and z2 at f2 [Hz]:
    zeta(w) = a0/(2 w) + a1 w/2 solved at w1 = 2 pi f1, w2 = 2 pi f2."""
    import math
    w1, w2 = 2 * math.pi * f1, 2 * math.pi * f2
    den = w2 * w2 - w1 * w1
    return 2 * w1 * w2 * (z1 * w2 - z2 * w1) / den, 2 * (z2 * w2 - z1 * w1) / den


def rayleigh_zeta(a0, a1, f):
    """Damping ratio of C = a0 M + a1 K at the frequency f [Hz] (an undamped mode of K, M)."""
    import numpy as np
    w = 2 * np.pi * np.asarray(f, float)
    return a0 / (2 * w) + a1 * w / 2


def _rayleigh_check(cfg):
    """One line when the Rayleigh options are given wrongly (None otherwise)."""
    coef = str(cfg.get("fem_rayleigh", "") or "").strip()
    freqs = str(cfg.get("fem_rayleigh_freqs", "") or "").strip()
    ratios = str(cfg.get("fem_rayleigh_ratios", "") or "").strip()
    if not (coef or freqs or ratios):
        return None
    others = [o for o in ("fem_alpha_m", "fem_damping_ratio") if cfg.user_set(o)]
    if coef and (freqs or ratios):
        return ("give Rayleigh damping either by its coefficients -ssi_fem_rayleigh a0,a1 or by "
                "-ssi_fem_rayleigh_freqs f1,f2 with -ssi_fem_rayleigh_ratios z1,z2, not both")
    if others:
        return (f"-ssi_{others[0]} and Rayleigh damping (-ssi_fem_rayleigh*) both set the damping: give one "
                "(a0 of -ssi_fem_rayleigh is the mass-proportional alpha_m)")
    if bool(freqs) != bool(ratios):
        return ("-ssi_fem_rayleigh_freqs f1,f2 and -ssi_fem_rayleigh_ratios z1,z2 go together: give both (or the "
                "coefficients -ssi_fem_rayleigh a0,a1)")
    if freqs:
        f1, f2 = parse_pair(freqs)
        z1, z2 = parse_pair(ratios)
        if not f1 < f2 or (f2 - f1) <= 1e-9 * f2:
            return (f"-ssi_fem_rayleigh_freqs {freqs}: give two different frequencies f1 < f2 (a Rayleigh "
                    "damping is fixed by its ratios at two frequencies)")
        a0, a1 = rayleigh_from_ratios(f1, f2, z1, z2)
        if a0 < -1e-12 * abs(a1) * (2 * 3.141592653589793 * f2) ** 2:
            return (f"-ssi_fem_rayleigh_ratios {ratios} at {freqs} Hz gives a0 = {a0:.4g} 1/s < 0: negative "
                    f"damping below {f1:g} Hz (need z2/z1 <= f2/f1)")
        if a1 < -1e-12 * abs(a0) / (2 * 3.141592653589793 * f1) ** 2:
            return (f"-ssi_fem_rayleigh_ratios {ratios} at {freqs} Hz gives a1 = {a1:.4g} s < 0: negative "
                    f"damping above {f2:g} Hz (need z2/z1 >= f1/f2)")
    a0, a1 = damping(cfg)[:2]
    if a1 > 0:
        a, d = cfg.fem_newmark_alpha, cfg.fem_newmark_delta
        integ = cfg.get("fem_integrator", "green")
        if integ == "green" and (abs(a - 0.25) > 1e-12 or abs(d - 0.5) > 1e-12):
            return (f"stiffness-proportional damping (a1 = {a1:.4g} s) with -ssi_fem_integrator green needs the "
                    f"trapezoidal rule (Newmark alpha 1/4, delta 1/2; got {a:g}, {d:g}); -ssi_fem_integrator "
                    "newmark takes any alpha, delta")
    return None


def damping(cfg):
    """(a0 [1/s], a1 [s], note): C = a0 M + a1 K from -ssi_fem_rayleigh, -ssi_fem_rayleigh_freqs/_ratios,
    -ssi_fem_damping_ratio/_freq or -ssi_fem_alpha_m (a1 = 0 for the last two), and a one-line note."""
    coef = str(cfg.get("fem_rayleigh", "") or "").strip()
    freqs = str(cfg.get("fem_rayleigh_freqs", "") or "").strip()
    if coef:
        a0, a1 = parse_pair(coef)
        return a0, a1, (f"Rayleigh damping C = a0 M + a1 K, a0 = {a0:.6g} 1/s, a1 = {a1:.6g} s (-ssi_fem_rayleigh)"
                        + _zeta_note(a0, a1))
    if freqs:
        f1, f2 = parse_pair(freqs)
        z1, z2 = parse_pair(cfg.fem_rayleigh_ratios)
        a0, a1 = rayleigh_from_ratios(f1, f2, z1, z2)
        return a0, a1, (f"Rayleigh damping C = a0 M + a1 K, zeta {z1:g} at {f1:g} Hz and {z2:g} at {f2:g} Hz: "
                        f"a0 = {a0:.6g} 1/s, a1 = {a1:.6g} s" + _zeta_note(a0, a1))
    am, note = alpha_m(cfg)
    return am, 0.0, note


def total_motion_damping_warning(cfg, a0, raw=None):
    """The warning for mass-proportional damping (a0 > 0) on a soil region of finite elements (-ssi_fem_cp/_cs
    or a part's cp, cs or layers) under seismic input in a coupled run (-ssi_problem ssi), else None: there
    the region's motion is total, so a0 M damps
    the ground's own motion against a fixed frame (a 1D soft layer's ratio tends to 1 / (1 + a0 rho1 H /
    (rho c_s)) < 1 as f -> 0: runs/soil_region/README.md). ``raw``: the part options (default: the
    options database's). A structure alone on a moving base (-ssi_problem fem) runs in relative motion, where
    a0 M is ordinary Rayleigh damping: no warning."""
    if not a0 > 0 or str(cfg.get("seismic", "none") or "none") == "none" or cfg.get("problem", "") != "ssi":
        return None
    if raw is None:
        from .parts import raw_part_options
        raw = raw_part_options()
    soil = float(cfg.get("fem_cs", 0.0) or 0.0) > 0 or any(k.endswith(("_cs", "_layers")) for k in raw)
    if not soil:
        return None
    return (f"mass-proportional damping (a0 = {a0:.4g} 1/s) on a soil region under seismic input damps the ground's own "
            f"motion (the region's total motion against a fixed frame): for the soil's damping use the stiffness-"
            f"proportional term alone, -ssi_fem_rayleigh 0,a1 (runs/soil_region/README.md)")


def _zeta_note(a0, a1):
    """'; zeta ... at ... Hz' at a few frequencies, and the frequency of least damping."""
    import math
    out = ""
    if a0 > 0 and a1 > 0:
        fmin = math.sqrt(a0 / a1) / (2 * math.pi)
        out += f"; least zeta {float(rayleigh_zeta(a0, a1, fmin)):.4g} at {fmin:.4g} Hz"
    return out


def alpha_m(cfg):
    """Mass-proportional damping alpha_m [1/s] and a one-line note of its origin."""
    if cfg.fem_damping_ratio > 0:
        import math
        am = 2.0 * cfg.fem_damping_ratio * 2.0 * math.pi * cfg.fem_damping_freq
        return am, (f"alpha_m = 2 zeta omega = 2*{cfg.fem_damping_ratio:g}*2pi*{cfg.fem_damping_freq:g} Hz "
                    f"= {am:.6g} 1/s")
    return cfg.fem_alpha_m, f"alpha_m = {cfg.fem_alpha_m:.6g} 1/s"
