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
    """Collective: print the predicted cost (time per stage, memory, whether it
    fits the nodes) of the case the options describe, without assembling
    (petsc_ssi/estimate.py)."""
    kind = problem_kind()
    if kind == "fem":
        raise SSIError("petsc-ssi estimate models the BEM half-space (-ssi_problem bem, and the BEM part of "
                       "-ssi_problem ssi); the FEM structure alone is cheap: run it with -log_view")
    from . import estimate as cost     # registers the -ssi_estimate_ options
    cfg = options.resolve(GROUPS[kind] + ("estimate",))
    if kind == "ssi":
        init().Sys.Print("[ssi] estimate: -ssi_problem ssi: the BEM half-space part only (no FEM, no coupling)")
    return cost.report(cfg, init().COMM_WORLD)
