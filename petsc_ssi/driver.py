"""Top-level driver: resolve options, dispatch on -ssi_problem."""
from . import options
from .petsc import init, SSIError

GROUPS = {"bem": ("common", "bem"), "fem": ("common", "fem"),
          "ssi": ("common", "bem", "fem", "ssi")}


def problem_kind():
    PETSc = init()
    kind = PETSc.Options().getString("ssi_problem", "bem").strip().lower()
    if kind not in GROUPS:
        raise SSIError(f"-ssi_problem {kind}: must be one of bem|fem|ssi")
    return kind


def run():
    """Collective: run the case described by the options database."""
    kind = problem_kind()
    cfg = options.resolve(GROUPS[kind])
    if kind == "bem":
        from .bem.run import run_bem
        return run_bem(cfg)
    if kind == "fem":
        from .fem.run import run_fem
        return run_fem(cfg)
    from .coupling.run import run_ssi
    return run_ssi(cfg)


def estimate():
    raise SSIError("petsc-ssi estimate is not available yet in this version")
