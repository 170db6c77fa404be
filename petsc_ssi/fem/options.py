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
register("fem_alpha_m", "real", 0.0, "1/s", "mass-proportional damping C = alpha_m M", G, validator=nonnegative)
register("fem_damping_ratio", "real", 0.0, "", "damping ratio zeta at -ssi_fem_damping_freq: alpha_m = 2 zeta "
         "omega (instead of -ssi_fem_alpha_m)", G, validator=nonnegative)
register("fem_damping_freq", "real", 0.0, "Hz", "reference frequency of -ssi_fem_damping_ratio", G,
         validator=nonnegative)
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
register("modes_n", "int", 6, "", "petsc-ssi modes: number of natural modes", G, validator=at_least(1))


def _fem_checks(cfg):
    if cfg.t_end < cfg.dt:
        return f"-ssi_t_end {cfg.t_end} is shorter than one step -ssi_dt {cfg.dt}"
    if cfg.fem_mesh != "box" and not os.path.isfile(cfg.fem_mesh):
        return f"-ssi_fem_mesh {cfg.fem_mesh}: no such file (relative to {os.getcwd()})"
    if cfg.user_set("fem_alpha_m") and cfg.fem_damping_ratio > 0:
        return "give either -ssi_fem_alpha_m or -ssi_fem_damping_ratio, not both"
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


def alpha_m(cfg):
    """Mass-proportional damping alpha_m [1/s] and a one-line note of its origin."""
    if cfg.fem_damping_ratio > 0:
        import math
        am = 2.0 * cfg.fem_damping_ratio * 2.0 * math.pi * cfg.fem_damping_freq
        return am, (f"alpha_m = 2 zeta omega = 2*{cfg.fem_damping_ratio:g}*2pi*{cfg.fem_damping_freq:g} Hz "
                    f"= {am:.6g} 1/s")
    return cfg.fem_alpha_m, f"alpha_m = {cfg.fem_alpha_m:.6g} 1/s"
