"""The coupled run's cost beyond the BEM (``petsc-ssi estimate`` for -ssi_problem ssi; issue 28).

The BEM half-space of a coupled run is counted by ``bem.cost`` from the coupled set-up itself
(``coupling.model.build_coupled``: the interface is the soil's traction region, as the run
assembles it). What the coupling adds is counted here, in three parts:

  structure    measured, not modelled: the estimate assembles K and M and factorises D as the run
               does (seconds on every structure this code meshes), and times solves with D
               (t_fs, the median of a few) and the growth of the resident memory (the factors)
  interface    3 n_I columns Z = A^-1 H_s e_j: 3 n_I BEM solves (bem.cost.bem_solve_seconds,
  set-up       the BEM model's solve) and, implicit, 3 n_I solves with D (t_fs); plus the dense
               products (flops / r_cpl)
  per step     n_fs solves with D (2: predictor and corrector), the dense interface products
               (Z's local rows: 2 (3 N / p) (3 n_I) flops twice; M3 and Z_II: 2 (3 n_I)^2 each,
               replicated) at r_cpl flop/s, the step's BEM residual (two products with the step
               matrices, part of c_cstep), the contact law and the step's bookkeeping c_cstep
  memory       the interface matrices (``interface_bytes``) and the structure's measured growth
               times the ranks

with n_I the interface nodes and N the soil nodes. The constants r_cpl and c_cstep come from
``estimate_constants.json`` ("coupled"), fitted to the coupled runs' logs by
``jobscripts/long_record.py --fit``."""
import statistics
import time

from ..sysmem import process_rss

FALLBACK = {"r_cpl": 2.0e9, "c_cstep": 4.0e-3, "n_fs": 2}


class CoupledCounts:
    """Collective: the structure's measured costs and the interface's counts of a coupled run
    (from ``build_coupled``'s (prob, model, iface, integrator); assembles and factorises the structure,
    nothing of the soil)."""

    def __init__(self, cfg, comm, prob, model, iface, integrator, n_solves=5):
        from ..fem.integrators import make_model_integrator
        mpi = comm.tompi4py()
        self.nI, self.N, self.steps = iface.n, prob.mesh.n_nodes, prob.n_steps
        self.implicit = cfg.coupling == "implicit"
        self.n_fem = model.dofmap.size
        self.ranks_measured = comm.getSize()
        r0 = process_rss()
        t0 = time.perf_counter()
        model.assemble()
        _, integ, _ = make_model_integrator(cfg, comm, prob.dt, model, integrator=integrator)
        mpi.Barrier()
        self.fem_setup_s = time.perf_counter() - t0
        self.fem_solve_s = solve_seconds(integ, comm, n_solves)
        self.fem_bytes = mpi.allreduce(max(process_rss() - r0, 0.0))        # summed over ranks
        integ.destroy()
        from .model import interface_bytes
        self._iface_bytes = lambda p: interface_bytes(cfg, prob, model, iface, p)

    def predict(self, c, p, bem_solve_s):
        """Seconds and bytes the coupling adds on p ranks ({'cpl_setup', 'cpl_loop', 'cpl_bytes'});
        ``c``: the constants, ``bem_solve_s``: one BEM step solve on p ranks (the BEM model's)."""
        k = dict(FALLBACK)
        k.update(c or {})
        n = 3 * self.nI
        flops_col = 2.0 * (3.0 * self.N / p) * n               # one product with Z's local rows
        setup = self.fem_setup_s + n * (bem_solve_s + (self.fem_solve_s if self.implicit else 0.0)) \
            + n * flops_col / k["r_cpl"]
        per_step = step_seconds(c, self.nI, self.N, p, self.fem_solve_s)
        return {"cpl_setup": setup, "cpl_loop": self.steps * per_step, "cpl_per_step": per_step,
                "cpl_bytes": self._iface_bytes(p) + self.fem_bytes * p / max(self.ranks_measured, 1)}


def solve_seconds(integ, comm, n_solves=5):
    """Collective: the median wall time of ``n_solves`` solves with the structure's step matrix D [s]
    (a random right-hand side on the free dofs)."""
    mpi = comm.tompi4py()
    b, x = integ.u.duplicate(), integ.u.duplicate()
    b.setRandom()
    b.pointwiseMult(b, integ.mask)
    times = []
    for _ in range(n_solves):
        mpi.Barrier()
        t1 = time.perf_counter()
        integ.solve(b, x)
        mpi.Barrier()
        times.append(time.perf_counter() - t1)
    for v in (b, x):
        v.destroy()
    return float(mpi.bcast(statistics.median(times)))        # (rank 0's: every rank predicts the same)


def step_seconds(c, n_i, n_soil, p, fem_solve_s):
    """Seconds the coupling adds to each step on p ranks (module docstring, 'per step'): n_fs solves with
    D, the dense interface products at r_cpl flop/s and c_cstep; ``c``: the constants (FALLBACK where
    they have none). ``petsc-ssi estimate`` and the coupled run's own prediction both use it."""
    k = dict(FALLBACK)
    k.update(c or {})
    n = 3 * n_i
    flops_col = 2.0 * (3.0 * n_soil / p) * n
    return k["n_fs"] * fem_solve_s + (2 * flops_col + 4.0 * n * n) / k["r_cpl"] + k["c_cstep"]


def describe(cc):
    """One line of what the coupling's counts are."""
    return (f"[ssi]   coupling: {cc.nI} interface nodes ({3 * cc.nI} columns), structure {cc.n_fem} dofs: "
            f"factorised in {cc.fem_setup_s:.3g} s, a solve {cc.fem_solve_s * 1e3:.3g} ms (measured on "
            f"{cc.ranks_measured} rank(s)), {'implicit' if cc.implicit else 'staggered'} coupling")

