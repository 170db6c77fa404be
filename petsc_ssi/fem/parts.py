"""Parts of the structure and their properties, from the options database.

``-ssi_fem_parts NAME,...`` names the physical groups of the structure's mesh
that carry elements. Each part takes its element and properties from
``-ssi_fem_part_<NAME>_<property>`` (PyLith binds materials to cell labels):

  element       hex8 | frame | shell            (required)
  E, nu, rho    Young's modulus [N/m^2], Poisson's ratio, density [kg/m^3]   (required)
  cp, cs        hex8: P- and S-wave speeds [m/s] instead of E and nu (a soil region: with rho)
  layers        hex8: horizontal layers 'z1:cp,cs,rho;z2:cp,cs,rho;...' instead of E, nu, rho (cp, cs):
                layer i holds the cells whose centroid lies between z_{i-1} (the first: any height)
                and z_i [m, elevations falling]; a soil region layered by depth (layers by part:
                one part per layer)
  thickness     shell thickness [m]                                           (shell, required)
  mass_per_area shell: mass per area [kg/m^2] used instead of rho * thickness
  section b,h   frame: rectangle of width b and depth h [m] (h along the orientation
                vector; area, Iy = b h^3/12, Iz = h b^3/12 and the exact St-Venant J)
  area, Iy, Iz, J   frame: section constants [m^2, m^4] (instead of, or overriding, section)
  orientation x,y,z frame: a vector not parallel to the member that fixes the section's
                depth direction (the local z axis, as a beam's "up"); default: global z,
                and global x for members parallel to z (columns)
  shear_factor  frame and shell: shear correction k (shear area k A; shell 5/6);
                frame: 0 = no shear deformation (Euler-Bernoulli)
  added_mass    non-structural mass: kg/m^2 on shells, kg/m on frames
  drilling      shell: scale of the drilling-rotation stiffness (default 1)
  release       frame, shell: 'rotations' hinges the part to the other frame and shell
                parts at the nodes they share (translations tied, rotations independent:
                a slab simply supported on its beams); released parts stay rigidly joined
                to each other; 'none' (default) joins monolithically. Point moments, point
                masses, receivers and output use the rotations of the parts that are not
                released. A released frame member hinged at both ends twists freely (a
                mechanism the static solve refuses): fix its torsion at one end

Without ``-ssi_fem_parts`` the structure is one hex8 part made of every brick
of the mesh with ``-ssi_fem_E/_nu/_rho`` or ``-ssi_fem_cp/_cs/_rho`` (the behaviour before parts
existed).
A part name may contain underscores; a misspelt part or property is an error
with a suggestion. Parsing is replicated (every rank reads the same database)
and raises SSIError before any mesh is read.
"""
import difflib
from dataclasses import dataclass

import numpy as np

from ..petsc import SSIError
from .elements import Props

KEY = "ssi_fem_part_"
ELEMENTS = ("hex8", "frame", "shell")

# property -> (kind, unit, meaning)
PROPERTIES = {
    "element": ("hex8|frame|shell", "", "element type of the part"),
    "E": ("real", "N/m^2", "Young's modulus"),
    "nu": ("real", "", "Poisson's ratio, in (-1, 0.5)"),
    "rho": ("real", "kg/m^3", "density"),
    "cp": ("real", "m/s", "hex8: P-wave speed, with cs instead of E and nu (a soil region)"),
    "cs": ("real", "m/s", "hex8: S-wave speed, with cp instead of E and nu (a soil region)"),
    "layers": ("z:cp,cs,rho;...", "m; m/s, m/s, kg/m^3", "hex8: layers by depth, each down to its elevation z "
               "(falling), instead of E, nu, rho: a cell goes to the layer of its centroid"),
    "thickness": ("real", "m", "shell thickness"),
    "mass_per_area": ("real", "kg/m^2", "shell: mass per area used instead of rho * thickness"),
    "section": ("b,h", "m", "frame: rectangle of width b and depth h (h along the orientation vector)"),
    "area": ("real", "m^2", "frame: cross-section area"),
    "Iy": ("real", "m^4", "frame: second moment about the local y axis (int z^2 dA, depth direction z)"),
    "Iz": ("real", "m^4", "frame: second moment about the local z axis (int y^2 dA)"),
    "J": ("real", "m^4", "frame: St-Venant torsion constant"),
    "orientation": ("x,y,z", "", "frame: vector fixing the local z (depth) axis; default z, x for vertical members"),
    "shear_factor": ("real", "", "shear correction factor k (frame: 0 = Euler-Bernoulli; default 5/6)"),
    "added_mass": ("real", "kg/m^2 | kg/m", "non-structural mass: per area on shells, per length on frames"),
    "drilling": ("real", "", "shell: scale of the drilling-rotation stiffness (default 1)"),
    "release": ("rotations|none", "", "frame, shell: hinge the part to the other frame/shell parts at shared nodes "
                "(translations tied, rotations released; default none: monolithic)"),
}
ALLOWED = {
    "hex8": ("element", "E", "nu", "rho", "cp", "cs", "layers"),
    "shell": ("element", "E", "nu", "rho", "thickness", "mass_per_area", "shear_factor", "added_mass", "drilling",
              "release"),
    "frame": ("element", "E", "nu", "rho", "section", "area", "Iy", "Iz", "J", "orientation", "shear_factor",
              "added_mass", "release"),
}
REQUIRED = {"hex8": ("E", "nu", "rho"), "shell": ("E", "nu", "rho", "thickness"), "frame": ("E", "nu", "rho")}
CELL_TYPE = {"hex8": "hex8", "shell": "quad4", "frame": "line2"}
DIM = {"hex8": 3, "shell": 2, "frame": 1}


@dataclass
class PartSpec:
    name: str
    element: str
    props: Props
    orientation_given: bool = False
    legacy: bool = False          # the single hex8 part of -ssi_fem_E/_nu/_rho
    layers: tuple = ()            # hex8 layered by depth: ((z_bottom [m], Props), ...), elevations falling
    section: tuple = ()           # frame: (b, h) [m] of -ssi_fem_part_NAME_section, () when area etc. are given
    speeds: bool = False          # hex8 given by its wave speeds (cp, cs, rho), not E and nu


def rect_section(b, h):
    """area, Iy, Iz, J of a b x h rectangle (h along the local z axis), J from the exact St-Venant
    series (``elements.frame.rect_section``)."""
    from .elements.frame import rect_section as exact
    return exact(b, h)


def _suggest(word, choices):
    near = difflib.get_close_matches(word, list(choices), n=1)
    return f" (did you mean {near[0]}?)" if near else ""


def _numbers(text, n, what):
    try:
        vals = [float(s) for s in str(text).split(",")]
    except ValueError:
        vals = []
    if len(vals) != n or not np.all(np.isfinite(vals)):
        raise SSIError(f"{what} '{text}': must be {n} comma-separated numbers")
    return vals


def _real(text, what):
    try:
        v = float(text)
    except ValueError:
        raise SSIError(f"{what} '{text}': not a number") from None
    if not np.isfinite(v):
        raise SSIError(f"{what} {text}: must be finite")
    return v


def part_names(cfg):
    return [s.strip() for s in str(cfg.get("fem_parts", "") or "").split(",") if s.strip()]


def raw_part_options(db=None):
    """{key without the leading 'ssi_fem_part_': value} from the PETSc options database."""
    if db is None:
        from ..petsc import init
        db = init().Options()
    from ..options import option_value
    allopts = db.getAll()
    return {k[len(KEY):]: option_value(db, k, allopts) for k in allopts if k.startswith(KEY)}


def _split_key(rest, names):
    """(part, property) of '<part>_<property>' for the longest matching part name."""
    best = None
    for name in names:
        if rest.startswith(name + "_") and (best is None or len(name) > len(best)):
            best = name
    if best is None:
        return None, None
    return best, rest[len(best) + 1:]


def elastic_from_wave_speeds(cp, cs, rho, what):
    """(E [N/m^2], nu) of an isotropic solid of wave speeds cp, cs [m/s] and density rho [kg/m^3]:
    nu = (cp^2 - 2 cs^2) / (2 (cp^2 - cs^2)), E = 2 rho cs^2 (1 + nu). SSIError naming ``what`` unless
    0 < cs and cp / cs > 2 / sqrt(3) (nu > -1 needs only cp > cs; nu < 0.5 any finite cp)."""
    if not (cs > 0 and cp > cs * np.sqrt(4.0 / 3.0) and rho > 0):
        raise SSIError(f"{what}: wave speeds cp {cp:g}, cs {cs:g} m/s and density {rho:g} kg/m^3 must have cs > 0, "
                       "cp > 2 cs / sqrt(3) (Poisson's ratio above -1 with a positive bulk modulus) and rho > 0")
    nu = (cp * cp - 2.0 * cs * cs) / (2.0 * (cp * cp - cs * cs))
    return 2.0 * rho * cs * cs * (1.0 + nu), nu


def _from_wave_speeds(g, opt):
    """A hex8 part given by cp, cs (and rho) as one given by E, nu (a soil region)."""
    both = [p for p in ("E", "nu") if p in g]
    if both or not ("cp" in g and "cs" in g and "rho" in g):
        raise SSIError(f"{opt('cp')}/{opt('cs')}: a part given by its wave speeds takes cp, cs and rho together "
                       f"and not E or nu" + (f" (also given: {', '.join(opt(p) for p in both)})" if both else ""))
    cp, cs, rho = (_real(g[p], opt(p)) for p in ("cp", "cs", "rho"))
    E, nu = elastic_from_wave_speeds(cp, cs, rho, f"part {opt('cp')[:-3]}")
    return {**{k: v for k, v in g.items() if k not in ("cp", "cs")}, "E": repr(E), "nu": repr(nu)}


def _legacy_props(cfg):
    """The box's single hex8 part: -ssi_fem_E/_nu/_rho, or -ssi_fem_cp/_cs/_rho (a soil region)."""
    cp, cs = float(cfg.get("fem_cp", 0.0) or 0.0), float(cfg.get("fem_cs", 0.0) or 0.0)
    if cp or cs:
        user = getattr(cfg, "user_set", lambda name: False)
        given = [f"-ssi_fem_{p}" for p in ("E", "nu") if user("fem_" + p)]
        if given:
            raise SSIError(f"-ssi_fem_cp/-ssi_fem_cs give the structure's E and nu: drop {' and '.join(given)}")
        if not user("fem_rho"):       # (the structure's default density would make another soil, silently)
            raise SSIError("-ssi_fem_cp/-ssi_fem_cs: a soil region given by its wave speeds takes cp, cs and "
                           "-ssi_fem_rho together (its density; the half-space's is -ssi_rho)")
        E, nu = elastic_from_wave_speeds(cp, cs, cfg.fem_rho, "-ssi_fem_cp/-ssi_fem_cs")
        return Props(E=E, nu=nu, rho=cfg.fem_rho)
    return Props(E=cfg.fem_E, nu=cfg.fem_nu, rho=cfg.fem_rho)


def parse_parts(cfg, raw=None):
    """Replicated: [PartSpec] of the options (SSIError on any bad or missing property)."""
    names = part_names(cfg)
    raw = raw_part_options() if raw is None else raw
    if not names:
        if raw:
            key = sorted(raw)[0]
            raise SSIError(f"-{KEY}{key} is set but -ssi_fem_parts names no part")
        speeds = bool(float(cfg.get("fem_cp", 0.0) or 0.0) or float(cfg.get("fem_cs", 0.0) or 0.0))
        return [PartSpec("structure", "hex8", _legacy_props(cfg), legacy=True, speeds=speeds)]
    if len(set(names)) != len(names):
        raise SSIError(f"-ssi_fem_parts '{cfg.fem_parts}': a part is named twice")
    given = {n: {} for n in names}
    for key, val in raw.items():
        part, prop = _split_key(key, names)
        if part is None:
            head = key.split("_")[0]
            raise SSIError(f"-{KEY}{key}: no part '{head}' in -ssi_fem_parts ({', '.join(names)})"
                           + _suggest(head, names))
        if prop not in PROPERTIES:
            raise SSIError(f"-{KEY}{key}: '{prop}' is not a part property" + _suggest(prop, PROPERTIES)
                           + "; petsc-ssi help lists them")
        given[part][prop] = val
    return [_spec(name, given[name]) for name in names]


def _spec(name, g):
    opt = lambda p: f"-{KEY}{name}_{p}"      # noqa: E731
    if "element" not in g:
        raise SSIError(f"part '{name}' has no element type: set {opt('element')} hex8|frame|shell")
    el = str(g["element"]).strip().lower()
    if el not in ELEMENTS:
        raise SSIError(f"{opt('element')} '{g['element']}': must be one of hex8|frame|shell" + _suggest(el, ELEMENTS))
    for p in g:
        if p not in ALLOWED[el]:
            raise SSIError(f"{opt(p)}: a {el} part has no property '{p}' (its properties: "
                           f"{', '.join(q for q in ALLOWED[el] if q != 'element')})")
    if "layers" in g:
        return _layered_spec(name, g, opt)
    speeds = "cp" in g or "cs" in g
    if speeds:
        g = _from_wave_speeds(g, opt)
    missing = [p for p in REQUIRED[el] if p not in g]
    if missing:
        raise SSIError(f"part '{name}' ({el}) needs {', '.join(opt(p) for p in missing)}")
    v = {p: _real(g[p], opt(p)) for p in g if p not in ("element", "section", "orientation", "release")}
    if not v["E"] > 0:
        raise SSIError(f"{opt('E')} {v['E']:g}: must be > 0")
    if not -1.0 < v["nu"] < 0.5:
        raise SSIError(f"{opt('nu')} {v['nu']:g}: Poisson's ratio must lie in (-1, 0.5)")
    if not v["rho"] >= 0:
        raise SSIError(f"{opt('rho')} {v['rho']:g}: must be >= 0")
    for p in ("thickness", "area", "Iy", "Iz", "J", "drilling"):
        if p in v and not v[p] > 0:
            raise SSIError(f"{opt(p)} {v[p]:g}: must be > 0")
    for p in ("added_mass", "mass_per_area", "shear_factor"):
        if p in v and not v[p] >= 0:
            raise SSIError(f"{opt(p)} {v[p]:g}: must be >= 0")
    if "mass_per_area" in v and v["mass_per_area"] == 0:      # 0 is the 'not set' of the shell: rho * t
        raise SSIError(f"{opt('mass_per_area')} 0: must be > 0 (0 does nothing: the shell's mass per area "
                       f"stays rho * thickness; for a massless shell set {opt('rho')} 0)")
    props = Props(E=v["E"], nu=v["nu"], rho=v["rho"])
    for p in ("thickness", "mass_per_area", "added_mass", "shear_factor", "drilling"):
        if p in v:
            setattr(props, p, v[p])
    if "release" in g:
        rel = str(g["release"]).strip().lower()
        if rel not in ("rotations", "none"):
            raise SSIError(f"{opt('release')} '{g['release']}': must be rotations or none"
                           + _suggest(rel, ("rotations", "none")))
        props.released = rel == "rotations"
    oriented = False
    bh = ()
    if el == "frame":
        sec = {}
        if "section" in g:
            b, h = _numbers(g["section"], 2, opt("section"))
            bh = (b, h)
            if not (b > 0 and h > 0):
                raise SSIError(f"{opt('section')} '{g['section']}': b and h must be > 0")
            sec = rect_section(b, h)
        for p in ("area", "Iy", "Iz", "J"):
            if p in v:
                sec[p] = v[p]
        missing = [p for p in ("area", "Iy", "Iz", "J") if p not in sec]
        if missing:
            raise SSIError(f"part '{name}' (frame) needs {opt('section')} b,h or "
                           f"{', '.join(opt(p) for p in missing)}")
        for p, val in sec.items():
            setattr(props, p, float(val))
        if "orientation" in g:
            o = np.array(_numbers(g["orientation"], 3, opt("orientation")))
            if np.linalg.norm(o) == 0:
                raise SSIError(f"{opt('orientation')} '{g['orientation']}': the zero vector fixes no axis")
            props.orientation = o
            oriented = True
    if el == "shell" and props.mass_per_area == 0 and props.rho == 0 and props.added_mass == 0:
        raise SSIError(f"part '{name}' (shell) has no mass: set {opt('rho')} > 0 or {opt('mass_per_area')}")
    if el != "shell" and props.rho == 0 and props.added_mass == 0:
        raise SSIError(f"part '{name}' ({el}) has no mass: {opt('rho')} must be > 0")
    return PartSpec(name, el, props, orientation_given=oriented, section=bh, speeds=speeds)


# Lower bounds that catch a wrong unit in a part's properties (an engineer's E in GPa ran without a word and
# sagged 1.5 km under its weight): E in GPa or MPa puts it below 1e6 N/m^2, t/m^3 for kg/m^3 puts rho below 10.
# Structural materials: rubber bearings near 1e6 N/m^2, timber and masonry 1e9-2e10, concrete 2-4e10, steel
# 2.1e11; densities 300 (timber, foam concrete) to 7850 (steel). No upper bounds: rigid links and lumped
# contents are modelled with large E, areas and densities on purpose. A warning, not a refusal (scaled and
# non-dimensional models run as given).
PART_E_MIN = 1e6                  # N/m^2
PART_RHO_MIN = 10.0               # kg/m^3 (0: a massless part, its mass given otherwise)


def plausibility(specs, size):
    """One line naming each part property below what structures have (a wrong unit), else None.
    ``size``: the structure's largest extent [m] (its bounding box's diagonal): a shell thicker than half of it,
    or a frame section (-ssi_fem_part_NAME_section b,h) wider or deeper than all of it (a pier wall of 6 m on a
    single-pier model 8 m across is a real section), is a length in mm or cm (an area given as such is not
    checked: rigid links take large ones). rho is not checked where mass_per_area or added_mass carry the
    part's mass (a token rho on a link or a shell)."""
    out = []
    for s in specs:
        layers = [p for _, p in s.layers] if getattr(s, "layers", None) else [s.props]
        opt = "-ssi_fem_" if s.legacy else f"-{KEY}{s.name}_"
        for k, p in enumerate(layers[:1] if s.legacy else layers):
            if not p.E >= PART_E_MIN:
                cs = f"c_s {np.sqrt(p.G() / p.rho):.3g} m/s" if s.element == "hex8" and p.rho > 0 else ""
                if getattr(s, "layers", None) and cs:       # (named as the user gave it: the layer's wave speeds)
                    out.append(f"{opt}layers layer {k + 1}: {cs} (E {p.E:g} N/m^2)")
                elif s.speeds and cs:
                    out.append(f"{opt}cs {cs[4:]} (E {p.E:g} N/m^2)")
                else:
                    out.append(f"{opt}E {p.E:g} N/m^2" + (f" ({cs})" if cs else ""))
            # (a shell's mass_per_area replaces rho t, and a light link's mass may sit in added_mass: rho is then
            # not the part's mass, and a token rho is no unit slip)
            own = not (getattr(p, "mass_per_area", 0) > 0 or getattr(p, "added_mass", 0) > 0)
            if own and p.rho != 0 and not p.rho >= PART_RHO_MIN:
                out.append(f"{opt}rho {p.rho:g} kg/m^3")
        p = s.props
        if size > 0 and s.element == "shell" and p.thickness > 0.5 * size:
            out.append(f"{opt}thickness {p.thickness:g} m on a structure {size:.3g} m across")
        if size > 0 and s.section and max(s.section) > size:
            out.append(f"{opt}section {s.section[0]:g},{s.section[1]:g} m on a structure {size:.3g} m across")
    if not out:
        return None
    out = list(dict.fromkeys(out))
    return ("unusual structure: " + "; ".join(out) + f" (structures: E above {PART_E_MIN:g} N/m^2, rho above "
            f"{PART_RHO_MIN:g} kg/m^3, sections and thicknesses well below the structure's size): check the units "
            "(N/m^2 = Pa, kg/m^3, m); a scaled or non-dimensional model runs as given")


def _layered_spec(name, g, opt):
    """A hex8 part layered by depth (``layers``: 'z1:cp,cs,rho;z2:cp,cs,rho;...'): each layer's Props
    from its wave speeds and density; its bottoms' elevations must fall."""
    other = [p for p in g if p not in ("element", "layers")]
    if other:
        raise SSIError(f"{opt('layers')}: each layer gives its cp, cs and rho; drop {', '.join(opt(p) for p in other)}")
    text = str(g["layers"]).strip()
    layers = []
    for k, item in enumerate(t for t in text.split(";") if t.strip()):
        z, sep, rest = item.partition(":")
        if not sep:
            raise SSIError(f"{opt('layers')} '{text}': layer {k + 1} '{item.strip()}' is not 'z:cp,cs,rho'")
        zb = _real(z.strip(), f"{opt('layers')} layer {k + 1}'s elevation")
        cp, cs, rho = _numbers(rest, 3, f"{opt('layers')} layer {k + 1}'s cp,cs,rho")
        E, nu = elastic_from_wave_speeds(cp, cs, rho, f"{opt('layers')} layer {k + 1}")
        if layers and not zb < layers[-1][0]:
            raise SSIError(f"{opt('layers')} '{text}': the layers' bottom elevations must fall (layer {k + 1} at "
                           f"z = {zb:g} m is not below {layers[-1][0]:g} m)")
        layers.append((zb, Props(E=E, nu=nu, rho=rho)))
    if not layers:
        raise SSIError(f"{opt('layers')} '{text}': no layer ('z:cp,cs,rho;...')")
    return PartSpec(name, "hex8", layers[0][1], layers=tuple(layers))


def layer_of(spec, z):
    """The layer index of cells whose centroids lie at elevations ``z`` [m] (int array), -1 below the
    last layer's bottom."""
    bottoms = np.array([zb for zb, _ in spec.layers])
    # layer i: z_i <= z < z_{i-1}; a centroid on a bottom (to round-off) belongs to the layer above
    tol = 1e-9 * max(1.0, float(np.abs(bottoms).max()))
    k = np.searchsorted(-bottoms, -(np.asarray(z, float) + tol), side="right")
    return np.where(k < len(bottoms), k, -1)


def help_text():
    """The per-part properties, for ``petsc-ssi help``."""
    lines = ["  [fem parts] -ssi_fem_parts NAME,... then -ssi_fem_part_NAME_<property>:"]
    for p, (kind, unit, meaning) in PROPERTIES.items():
        who = ", ".join(e for e in ELEMENTS if p in ALLOWED[e])
        req = ", ".join(e for e in ELEMENTS if p in REQUIRED[e] or p == "element")
        u = f" [{unit}]" if unit else ""
        lines.append(f"  -ssi_fem_part_NAME_{p} <{kind}>{u}: {meaning} ({who}"
                     + (f"; required for {req}" if req else "") + ")")
    return "\n".join(lines)


from ..options import register_help_section  # noqa: E402  (-help lists the per-part options)
register_help_section(help_text)
