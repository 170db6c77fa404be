"""The one registry of petsc_ssi options (prefix ``-ssi_``).

Every option is declared once, here or in the module that owns it, through
``register``: name, type, default, unit, help text and an optional validator
(PyLith's ``meta["tip"]`` + validators). ``resolve`` reads the PETSc options
database, converts and validates every option of the groups a command uses,
runs the cross-checks, and raises the same one-line ``SSIError`` on every rank
before any heavy work. ``-help`` prints the registry (petsc4py has no
PetscOptionsBegin); ``markdown_table`` generates the README table.

Misspelt ``-ssi_`` options are an error (with a suggestion), so a typo never
silently runs the default case.
"""
import difflib
import math
from dataclasses import dataclass, field

from .petsc import init, SSIError, collective_error, warn, _APPLIED_DEFAULTS

PREFIX = "ssi_"
PART_PREFIX = "fem_part_"     # -ssi_fem_part_<NAME>_<property>: checked by fem/parts.py

_REGISTRY = {}
_CHECKS = []


@dataclass
class Option:
    name: str              # without the -ssi_ prefix
    kind: str              # real | int | bool | str | enum | path
    default: object
    unit: str = ""
    help: str = ""
    group: str = "run"
    choices: tuple = ()
    validator: object = None   # callable(value) -> None or error text
    aliases: tuple = field(default_factory=tuple)


def register(name, kind, default, unit="", help="", group="run", choices=(),
             validator=None):
    if name in _REGISTRY:
        old = _REGISTRY[name]
        if (old.kind, old.default) != (kind, default):
            raise ValueError(f"option -ssi_{name} registered twice differently")
        return old
    opt = Option(name, kind, default, unit, help, group, tuple(choices), validator)
    _REGISTRY[name] = opt
    return opt


def register_check(groups, func):
    """A cross-check ``func(cfg) -> None | str`` run when all ``groups`` resolve."""
    _CHECKS.append((tuple(groups), func))


def positive(v):
    return None if v > 0 else "must be > 0"


def nonnegative(v):
    return None if v >= 0 else "must be >= 0"


def at_least(n):
    return lambda v: None if v >= n else f"must be >= {n}"


def options():
    return dict(_REGISTRY)


class Config:
    """Resolved option values (attribute access) and where each came from."""

    def __init__(self, values, sources):
        self._values = values
        self._sources = sources

    def __getattr__(self, name):
        try:
            return self.__dict__["_values"][name]
        except KeyError:
            raise AttributeError(name) from None

    def get(self, name, default=None):
        return self._values.get(name, default)

    def set(self, name, value):
        self._values[name] = value

    def user_set(self, name):
        return self._sources.get(name) == "user"

    def as_dict(self):
        return dict(self._values)

    def sources(self):
        return dict(self._sources)


def _convert(opt, text):
    if opt.kind == "real":
        v = float(text)
        if not math.isfinite(v):
            raise ValueError(f"'{text}' is not a finite number")
        return v
    if opt.kind == "int":
        return int(text)
    if opt.kind == "bool":
        t = str(text).strip().lower()
        if t in ("", "1", "true", "yes", "on"):
            return True
        if t in ("0", "false", "no", "off"):
            return False
        raise ValueError(f"'{text}' is not a boolean")
    if opt.kind == "enum":
        t = str(text).strip().lower()
        if t not in opt.choices:
            raise ValueError(f"'{text}' is not one of {'|'.join(opt.choices)}")
        return t
    return str(text)


_HELP_SECTIONS = []


def register_help_section(fn):
    """Add ``fn()`` (a block of text) to ``-help`` after the option table: options whose names are
    not fixed (e.g. the per-part ``-ssi_fem_part_<NAME>_<property>``). The registry imports no
    domain module: each declares its options, and its help, when it is imported."""
    if fn not in _HELP_SECTIONS:
        _HELP_SECTIONS.append(fn)


def resolve(groups=None, comm=None):
    """Collective: read, convert and validate the options of ``groups``.

    Raises ``SSIError`` (same message on every rank) on an unknown ``-ssi_``
    option, a value that does not convert, a failed validator or cross-check.
    """
    PETSc = init()
    comm = comm or PETSc.COMM_WORLD
    db = PETSc.Options()
    allopts = db.getAll()
    err = None
    for key in allopts:
        if key.startswith(PREFIX):
            name = key[len(PREFIX):]
            if name in _REGISTRY or _is_petsc_object_option(name) or name.startswith(PART_PREFIX):
                continue
            near = difflib.get_close_matches(name, list(_REGISTRY), n=1)
            hint = f" (did you mean -ssi_{near[0]}?)" if near else ""
            err = f"unknown option -{key}{hint}; -help lists every -ssi_ option"
            break
    if err is None:
        err = _unprefixed_solver_option(allopts)
    if err is None:
        err = _solver_type_error(allopts)
    values, sources = {}, {}
    if err is None:
        for name, opt in _REGISTRY.items():
            if groups is not None and opt.group not in groups and opt.group != "common":
                continue
            key = PREFIX + name
            if key in allopts:
                try:
                    raw = option_value(db, key, allopts)
                except SSIError as exc:
                    err = str(exc)
                    break
                try:
                    val = _convert(opt, raw)
                except ValueError as exc:
                    err = f"-ssi_{name}: {exc}"
                    break
                sources[name] = "user"
            else:
                val = opt.default
                sources[name] = "default"
            if opt.validator is not None and val is not None:
                msg = opt.validator(val)
                if msg:
                    err = f"-ssi_{name} {val}: {msg}"
                    break
            values[name] = val
    cfg = Config(values, sources)
    if err is None:
        for grps, func in _CHECKS:
            if groups is not None and not set(grps) <= set(groups) | {"common"}:
                continue
            msg = func(cfg)
            if msg:
                err = msg
                break
    collective_error(err, comm)
    if groups is not None:
        _warn_other_groups(allopts, groups, comm)
    return cfg


# PETSc object options that only a solver object reads: every solver of petsc-ssi has a prefix
# (-ssi_bem_, -ssi_fem_, -ssi_modes_), so without one they reach nothing
_SOLVER_OPTIONS = ("ksp_", "pc_", "eps_", "st_", "snes_", "ts_", "tao_")
_SOLVER_HINT = "-ssi_bem_ for the soil's step solve, -ssi_fem_ for the structure's, -ssi_modes_ for petsc-ssi modes"


def _unprefixed_solver_option(allopts):
    """The error for a solver option without petsc-ssi's prefix (-ksp_type, -pc_factor_...), or None."""
    bad = sorted(k for k in allopts if k.startswith(_SOLVER_OPTIONS))
    if not bad:
        return None
    return (f"-{bad[0]}: no solver of petsc-ssi reads PETSc options without its prefix; write "
            f"-ssi_bem_{bad[0]} or -ssi_fem_{bad[0]} ({_SOLVER_HINT})"
            + (f" (also: {' '.join('-' + k for k in bad[1:])})" if len(bad) > 1 else ""))


_TYPED = {"ksp_type": ("KSP", "Type"), "pc_type": ("PC", "Type"), "pc_factor_mat_solver_type": ("Mat", "SolverType")}


def _solver_type_error(allopts):
    """The error for a petsc-ssi solver's KSP, PC or factor package type that PETSc does not know
    (-ssi_bem_pc_type foo), before any work: PETSc itself would refuse it only when the solver is made, after the
    assembly, and on some ranks with an MPI abort. The names are petsc4py's; whether a known package was built
    into this PETSc (MUMPS, SuperLU_dist) is still PETSc's to say."""
    PETSc = init()
    for key in sorted(allopts):
        if not key.startswith(PREFIX) or not _is_petsc_object_option(key[len(PREFIX):]):
            continue
        what = next((t for t in _TYPED if key.endswith("_" + t)), None)
        if what is None:
            continue
        cls, attr = _TYPED[what]
        known = {v for k, v in vars(getattr(getattr(PETSc, cls), attr)).items()
                 if not k.startswith("_") and isinstance(v, str)}
        val = str(allopts[key]).strip()
        if val and val.lower() not in known:
            near = difflib.get_close_matches(val.lower(), sorted(known), n=1)
            return (f"-{key} {val}: PETSc has no {what.replace('_', ' ')} '{val}'"
                    + (f" (did you mean {near[0]}?)" if near else "") + f"; PETSc's are: {', '.join(sorted(known))}")
    return None


_READ_GROUPS = set()        # the option groups this process has resolved (a command may resolve twice)
_WARNED = set()


def _warn_other_groups(allopts, groups, comm):
    """One warning line naming the -ssi_ options the user set that belong to groups this command does
    not read (-ssi_fem_* in a BEM run, -ssi_lags_load in a FEM run): they do nothing here. Each
    option is named once per process; groups an earlier resolve read are not named."""
    _READ_GROUPS.update(groups)
    idle = []
    for key in allopts:
        name = key[len(PREFIX):] if key.startswith(PREFIX) else None
        opt = _REGISTRY.get(name)
        if opt is None or opt.group in _READ_GROUPS or opt.group == "common" or key in _WARNED:
            continue
        idle.append((opt.group, key))
    if idle:
        _WARNED.update(k for _, k in idle)
        idle.sort()
        theirs = ", ".join(sorted({g for g, _ in idle}))
        ours = ", ".join(sorted(set(groups) - {"common"}))
        warn(f"options this run does not read ({theirs} options; it reads the common and {ours} ones): "
             + " ".join("-" + k for _, k in idle), comm)


GETSTRING_MAX = 1023


def option_value(db, key, allopts=None):
    """The value of option ``key`` (without '-'): petsc4py's getString keeps spaces but cuts values
    at 1023 characters; getAll keeps long values but splits at whitespace. The longer of the two
    is the value; a value that is both longer than 1023 characters and contains whitespace cannot
    be read whole: SSIError (remove the spaces)."""
    allopts = db.getAll() if allopts is None else allopts
    a = db.getString(key, "") or ""
    b = allopts.get(key) or ""
    if len(a) < GETSTRING_MAX or b == a:
        return a
    if len(b) > len(a):
        return b
    raise SSIError(f"-{key}: the value is longer than {GETSTRING_MAX} characters and contains spaces; "
                   "write it without spaces (petsc4py cannot return it whole otherwise)")


def _is_petsc_object_option(name):
    # -ssi_bem_ksp_type, -ssi_fem_pc_type, -ssi_bem_columns_pc_type (coupling/columns.py), ...: options of PETSc objects that
    # carry a petsc_ssi prefix belong to PETSc, not to this registry.
    for pfx in ("bem_columns_", "bem_", "fem_", "coupling_", "modes_"):
        if name.startswith(pfx):
            rest = name[len(pfx):]
            if rest.split("_")[0] in ("ksp", "pc", "mat", "eps", "st", "snes", "vec", "redundant", "sub"):
                return True
    return False


def help_text():
    lines = ["petsc_ssi options (prefix -ssi_); PETSc's own options follow with -help", ""]
    bygroup = {}
    for opt in _REGISTRY.values():
        bygroup.setdefault(opt.group, []).append(opt)
    for grp in sorted(bygroup):
        lines.append(f"  [{grp}]")
        for opt in sorted(bygroup[grp], key=lambda o: o.name):
            kind = "|".join(opt.choices) if opt.kind == "enum" else opt.kind
            unit = f" [{opt.unit}]" if opt.unit else ""
            lines.append(f"  -ssi_{opt.name} <{opt.default}> ({kind}){unit}: {opt.help}")
        lines.append("")
    for fn in _HELP_SECTIONS:
        lines.append(fn())
        lines.append("")
    return "\n".join(lines)


def markdown_table(groups=None):
    """The README's option table, generated from the registry."""
    rows = ["| option | default | unit | meaning |", "|---|---|---|---|"]
    for opt in sorted(_REGISTRY.values(), key=lambda o: (o.group, o.name)):
        if groups is not None and opt.group not in groups:
            continue
        kind = "|".join(opt.choices) if opt.kind == "enum" else opt.kind
        rows.append(f"| `-ssi_{opt.name}` ({kind}) | `{opt.default}` | {opt.unit} | {opt.help} |")
    return "\n".join(rows)


__all__ = ["register", "register_check", "resolve", "help_text", "markdown_table",
           "Config", "SSIError", "positive", "nonnegative", "at_least"]


def _options_used():
    """A function name -> whether PETSc queried the option, or None where it cannot be known:
    petsc4py's ``Options.used`` where it exists, else PETSc's ``PetscOptionsUsed`` through ctypes
    (petsc4py 3.18 does not wrap it) from the libpetsc this process loaded (Linux)."""
    PETSc = init()
    db = PETSc.Options()
    if hasattr(db, "used"):
        return lambda name: bool(db.used(name))
    try:
        import ctypes
        with open("/proc/self/maps") as fh:
            path = next((ln.split()[-1] for ln in fh if "/libpetsc" in ln and ".so" in ln), None)
        if path is None:
            return None
        fn = ctypes.CDLL(path).PetscOptionsUsed
        fn.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.POINTER(ctypes.c_int)]
        fn.restype = ctypes.c_int

        def used(name):
            flag = ctypes.c_int(0)
            return fn(None, name.encode(), ctypes.byref(flag)) == 0 and bool(flag.value)
        return used
    except (OSError, AttributeError):
        return None


def unused_petsc_options():
    """The PETSc object options under our prefixes (-ssi_bem_ksp_..., -ssi_fem_pc_..., ...) that
    nothing read, e.g. misspelt ones (-ssi_bem_ksp_tpye); None where it cannot be known."""
    used = _options_used()
    if used is None:
        return None
    keys = [k for k in init().Options().getAll() if k.startswith(PREFIX) and _is_petsc_object_option(k[len(PREFIX):])
            and k not in _APPLIED_DEFAULTS]           # our own defaults: not the user's to worry about
    return sorted(k for k in keys if not used(k))


def warn_unused_options(comm=None):
    """Collective (same options on every rank): one warning line naming the unused ones."""
    left = unused_petsc_options()
    if left:
        warn("options set but never used (misspelt, or for a solver this run does not have): "
             + " ".join("-" + k for k in left), comm)
