"""The environment for the processes petsc_ssi's scripts start (runs, mpirun), with an MPI singleton's variables left out.

A process that has initialised MPI without mpirun (``from mpi4py import MPI``, ``petsc4py.init``: an MPI singleton)
is given, by OpenMPI 4.1 (Debian 12), some thirty variables in its C environment: ``OMPI_MCA_ess=singleton``, the
singleton's ``OMPI_MCA_orte_*``, ``OMPI_MCA_pmix`` and its PMIx server's ``PMIX_*``. Python's ``os.environ`` does not
see them, but ``subprocess`` without ``env=`` passes the C environment on, and an mpirun started with
``OMPI_MCA_ess=singleton`` exits with status 1 without printing a line (measured: ``python
jobscripts/singleton_mpirun.py``; every other one of those variables alone leaves it working). That was the slow
tier's flaky soft-layer test: its mpirun failed whenever an earlier test of the same pytest process had initialised
MPI in it, and passed alone.

``child_env()`` starts from ``os.environ`` (Python's view: the variables the process was started with and those it set)
and drops an inherited singleton's variables too (a process started by a singleton has them in ``os.environ``).
"""
import os

# what OpenMPI 4.1's singleton sets beside its PMIx server's PMIX_* (jobscripts/singleton_mpirun.py prints the list)
SINGLETON_VARS = ("OMPI_MCA_ess", "OMPI_MCA_orte_ess_num_procs", "OMPI_MCA_orte_launch",
                  "OMPI_MCA_orte_precondition_transports", "OMPI_MCA_pmix", "OMPI_APP_CTX_NUM_PROCS",
                  "ORTE_SCHIZO_DETECTION", "HFI_NO_BACKTRACE", "IPATH_NO_BACKTRACE")


def child_env(base=None, **extra):
    """A copy of ``base`` (default ``os.environ``) for a child process, without an MPI singleton's variables
    (``OMPI_MCA_ess=singleton`` marks them; then ``SINGLETON_VARS`` and every ``PMIX_*`` go), with ``extra`` set."""
    env = dict(os.environ if base is None else base)
    if env.get("OMPI_MCA_ess") == "singleton":
        for k in list(env):
            if k in SINGLETON_VARS or k.startswith("PMIX_"):
                del env[k]
    env.update({k: str(v) for k, v in extra.items()})
    return env
