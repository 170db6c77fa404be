"""The table of problem kinds, declared once: ``-ssi_problem`` -> the problem class and the option
groups it reads; ``from_options`` makes the problem the options database describes, ``run`` runs it.

A new kind of problem is a class on ``petsc_ssi.problem.TransientProblem`` in its package and one
row here.
"""
from ..petsc import init, SSIError
from .. import options
from ..bem.problem import BEMTransient
from ..fem.problem import FEMTransient
from ..coupling.problem import SSITransient

# kind: (class, option groups of the registry it reads)
KINDS = {"bem": (BEMTransient, ("common", "bem", "seismic")),
         "fem": (FEMTransient, ("common", "fem", "seismic")),
         "ssi": (SSITransient, ("common", "bem", "fem", "ssi", "seismic"))}
GROUPS = {k: g for k, (_, g) in KINDS.items()}


def problem_kind():
    """Collective: -ssi_problem (default bem), checked."""
    PETSc = init()
    kind = PETSc.Options().getString("ssi_problem", "bem").strip().lower()
    if kind not in KINDS:
        raise SSIError(f"-ssi_problem {kind}: must be one of {'|'.join(KINDS)}")
    return kind


def problem_class(kind):
    if kind not in KINDS:
        raise SSIError(f"-ssi_problem {kind}: must be one of {'|'.join(KINDS)}")
    return KINDS[kind][0]


def resolve(kind, extra=()):
    """Collective: the resolved options of a problem kind (and of the ``extra`` groups)."""
    return options.resolve(GROUPS[kind] + tuple(extra))


def from_options(comm=None):
    """Collective: the problem the options database describes (-ssi_problem and its options,
    resolved and checked), constructed but not set up."""
    kind = problem_kind()
    return problem_class(kind)(resolve(kind), comm)


def run_problem(kind, cfg, comm=None):
    """Collective: the whole run of ``cfg`` (a kind's resolved options); returns its results. With
    -ssi_check_stability (BEM) only the stability check's surrogate runs."""
    PETSc = init()
    comm = comm or PETSc.COMM_WORLD
    if kind == "bem" and cfg.get("check_stability"):
        from ..bem.stability import check_stability     # a coarse surrogate only
        return check_stability(cfg, comm, lambda c: run_problem("bem", c, comm))
    return problem_class(kind)(cfg, comm).run()


def run_bem(cfg, comm=None):
    """Collective: the half-space run of ``cfg`` (``BEMTransient``; -ssi_check_stability honoured)."""
    return run_problem("bem", cfg, comm)


def run_fem(cfg, comm=None):
    """Collective: the structure's run of ``cfg`` (``FEMTransient``)."""
    return run_problem("fem", cfg, comm)


def run_ssi(cfg, comm=None):
    """Collective: the coupled run of ``cfg`` (``SSITransient``)."""
    return run_problem("ssi", cfg, comm)


def run():
    """Collective: run the case described by the options database."""
    kind = problem_kind()
    return run_problem(kind, resolve(kind))
