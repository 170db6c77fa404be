"""Options of the FEM-BEM coupling (group "ssi"), declared once in the registry.

The soil is the BEM half-space (``-ssi_cp/_cs/_rho/_mesh...``), the structure
the FEM model (``-ssi_fem_*``); these options say how they meet.
"""
import numpy as np

from ..options import register, register_check, positive
from ..bem import options as _bem_options  # noqa: F401  (the coupled problem reads the soil's options
from ..fem import options as _fem_options  # noqa: F401   and the structure's)

G = "ssi"

register("interface", "str", "auto", "", "soil elements of the soil-structure interface: 'auto' (every "
         "element whose nine nodes all coincide with nodes of -ssi_fem_interface), a group name or "
         "'box:x0,x1,y0,y1'", G)
register("fem_interface", "str", "base", "", "group(s) of the structure in contact with the soil: brick faces, "
         "or the shell cells of a foundation slab", G)
register("interface_offset", "bool", False, "", "shell foundation slab: the soil touches the slab's underside, "
         "u + theta x (-t/2 n) (rotations coupled through the offset); off: the slab's mid-surface "
         "translations", G)
register("interface_tol", "real", 1e-6, "", "FE and BE interface nodes match when closer than this times "
         "the smallest interface node spacing", G, validator=positive)
register("interface_stride", "int", 1, "steps", "keep the interface's nodal series (u_f, u_b, p, gap, p_N, "
         "status, u_ff) every this many steps (1: every step); the resultants, iterations and open-node "
         "counts are kept every step. A long record's interface series grows by 3 n_I doubles per key and "
         "step: e.g. -ssi_interface_stride 10 with -ssi_output_stride 10", G,
         validator=lambda v: None if v >= 1 else "must be >= 1")
register("step_times", "bool", False, "", "write the wall time of every step into the output (timing/step_wall, "
         "s): whether a long record's cost per step stays flat (benchmarks; it differs between reruns)", G)
register("contact", "enum", "bonded", "", "interface law: bonded (u_b = u_f always; linear) or unilateral "
         "(Kuhn-Tucker contact with a cohesion limit: the structure may lift off, paper eq. 25)", G,
         choices=("bonded", "unilateral"))
register("contact_cohesion", "real", 0.0, "N/m^2", "cohesion limit p_C: a closed node opens when its normal "
         "traction (tension positive) exceeds p_C", G,
         validator=lambda v: None if v >= 0 else "must be >= 0")
G_N = 9.81                                   # m/s^2: the weight preload's gravity


def parse_preload(text):
    """-ssi_contact_preload: None ('none'), 'weight', ('earth', K0) from 'earth:K0', or a pressure [N/m^2] >= 0;
    ValueError in words."""
    t = str(text).strip().lower()
    if t in ("none", ""):
        return None
    if t == "weight":
        return "weight"
    if t.startswith("earth:"):
        try:
            k0 = float(t[6:])
        except ValueError:
            k0 = -1.0
        if not (np.isfinite(k0) and 0.0 <= k0 <= 10.0):
            raise ValueError(f"earth:K0 takes the lateral earth pressure coefficient K0 in [0, 10], not '{t[6:]}'")
        return ("earth", k0)
    try:
        v = float(t)
    except ValueError:
        raise ValueError("expected none, weight, earth:K0 or a pressure in N/m^2") from None
    if not np.isfinite(v) or v < 0:
        raise ValueError("the preload is a compression: it must be a finite pressure >= 0 N/m^2")
    return v


def _preload_ok(text):
    try:
        parse_preload(text)
    except ValueError as exc:
        return str(exc)
    return None


register("contact_preload", "str", "none", "N/m^2", "static contact pressure under the dynamic increment "
         "(unilateral contact): none (tractions are increments from rest: any tension beyond p_C opens), "
         "weight (the structure's total mass x 9.81 m/s^2 spread uniformly over the interface area), "
         "earth:K0 (a structure in an excavation: per node n_z^2 q + (1 - n_z^2) K0 rho g |z|, the lateral earth "
         "pressure K0 rho g |z| of the soil's -ssi_rho on walls and q on the bottom, q such that the vertical "
         "resultant is the weight) or a pressure in N/m^2; a node opens when its dynamic normal tension exceeds preload + p_C, and an open "
         "node carries total traction zero (dynamic traction = the preload's relief)", G,
         validator=_preload_ok)
register("contact_open_traction", "enum", "zero", "", "traction an open node carries: zero (p_C is a "
         "strength lost on opening) or cohesion (the normal tension p_C, eq. 25 read literally: "
         "(p_C - p_N) g = 0 with g > 0)", G, choices=("zero", "cohesion"))
register("contact_separation", "enum", "free", "", "what an open node keeps of the bond: free (no "
         "traction in any direction: the tangential traction is released with the normal one) or auto (free, "
         "but a node that then penetrates keeps its tangential bond and releases its normal traction only, "
         "for the rest of the step: on walls a node's shear, released, can push it into the soil, and the "
         "free law has no consistent status there) or normal (every open node keeps its tangential bond)", G,
         choices=("free", "auto", "normal"))
register("contact_tol", "real", 1e-8, "", "relative tolerance of the contact checks: gap < -tol max|u_f| "
         "closes a node, p_N > p_C + preload + tol max(|p|, p_C, preload) opens one", G, validator=positive)
register("contact_max_iter", "int", 25, "", "active-set iterations per step before the step is accepted with "
         "a warning (cycling)", G, validator=lambda v: None if v >= 1 else "must be >= 1")
register("interface_columns", "enum", "auto", "", "how the interface columns Z = A^-1 H_s E_I are solved: "
         "region (on the soil DOFs within a margin of the interface, with their own LU: A^-1 decays "
         "geometrically, the truncation's residual is checked and the margin doubled until it is at round-off, "
         "coupling/columns.py), full (with the step matrix's factors, every row) or auto (region when it holds at "
         "most 60 % of the soil's DOFs)", G, choices=("auto", "region", "full"))
register("interface_columns_margin", "real", 4.0, "", "the region's first margin, in reaches of the step "
         "matrix (the largest distance between two nodes it couples)", G, validator=positive)
register("coupling", "enum", "implicit", "", "time coupling: implicit (the structure's interface "
         "displacement and the soil traction of a step solved together on the interface; structure by the "
         "trapezoidal rule in midpoint form with the traction as the interval-mean force) or staggered (the "
         "paper's Table 2: FEM predictor, BEM, force as an impulse; Green's-function integrator; stable only "
         "while the soil's impedance times dt stays below about twice the interface nodal masses)", G,
         choices=("implicit", "staggered"))
register("coupling_traction", "enum", "direct", "", "interface force handed to the structure: "
         "direct (p^n, as printed in Table 2) or extrapolated (1.5 p^n - 0.5 p^{n-1}: the load at t_n; "
         "staggered coupling only)", G,
         choices=("direct", "extrapolated"))
register("structure_receivers", "str", "", "m", "structure receivers 'x,y,z;...' (nearest FE node) or "
         "'group:NAME'; "
         "-ssi_receivers are soil surface points", G)


def _ssi_checks(cfg):
    if cfg.get("disp_rigid", "prescribed") != "prescribed":
        return ("-ssi_disp_rigid massless is for the half-space alone (-ssi_problem bem, petsc-ssi input-motion); "
                "in a coupled run the structure moves the interface")
    if cfg.disp_group:
        return ("-ssi_disp_group prescribes soil displacements; with -ssi_problem ssi the interface "
                "displacements come from the structure (-ssi_interface)")
    from ..bem.symmetry import parse
    from ..petsc import SSIError
    try:
        planes = parse(cfg.symmetry)
    except SSIError as exc:
        return str(exc)
    if cfg.contact == "unilateral" and any(kind < 0 for _, kind in planes):
        return ("-ssi_contact unilateral with an antisymmetry plane (-ssi_symmetry "
                f"{cfg.symmetry}): contact destroys the antisymmetry of the response (the side in "
                "compression stays closed, the other may open), so an antisymmetric half model is "
                "wrong; mesh the whole interface")
    if cfg.contact == "unilateral" and cfg.contact_separation != "free" and planes:
        return (f"-ssi_contact_separation {cfg.contact_separation} with -ssi_symmetry {cfg.symmetry}: a stuck node's "
                "frame ignores the dofs a symmetry plane fixes (not implemented); mesh the whole interface or use "
                "-ssi_contact_separation free")
    if cfg.contact != "unilateral" and parse_preload(cfg.contact_preload) is not None:
        return (f"-ssi_contact_preload {cfg.contact_preload} needs -ssi_contact unilateral (a bonded interface "
                f"is linear: the static pressure does not change its dynamic response)")
    if cfg.user_set("fem_integrator") and cfg.coupling == "staggered" and cfg.fem_integrator != "green":
        return ("-ssi_coupling staggered integrates the structure with green (u^n independent of the force "
                f"of step n); drop -ssi_fem_integrator {cfg.fem_integrator}")
    if cfg.user_set("fem_integrator") and cfg.coupling == "implicit":
        return ("-ssi_coupling implicit integrates the structure with the trapezoidal rule in midpoint form "
                f"(the interface force as an interval mean); drop -ssi_fem_integrator {cfg.fem_integrator}")
    if cfg.coupling == "implicit" and cfg.coupling_traction == "extrapolated":
        return ("-ssi_coupling_traction extrapolated is for -ssi_coupling staggered; the implicit step takes "
                "the traction as the mean force over the step, which it is")
    return None


CONTACT_ONLY = ("contact_cohesion", "contact_open_traction", "contact_tol", "contact_max_iter", "contact_separation")


def ignored_contact_options(cfg):
    """The unilateral-contact options the user set on a bonded interface (they do nothing: a study
    that switches one options file between the two laws keeps them; the run warns)."""
    if cfg.contact == "unilateral":
        return []
    return [f"-ssi_{n}" for n in CONTACT_ONLY if cfg.user_set(n)]


register_check((G,), _ssi_checks)
