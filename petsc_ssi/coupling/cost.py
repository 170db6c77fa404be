"""The coupled run's cost beyond the BEM (``petsc-ssi estimate`` for -ssi_problem ssi; issue 28).

The BEM half-space of a coupled run is counted by ``bem.cost`` from the coupled set-up itself
(``coupling.model.build_coupled``: the interface is the soil's traction region, as the run
assembles it). What the coupling adds is counted here, in three parts:

  structure    measured, not modelled: the estimate assembles K and M and factorises D as the run
               does (seconds on every structure this code meshes), and times solves with D
               (t_fs, the median of a few) and the growth of the resident memory (the factors)
  interface    3 n_I columns Z = A^-1 H_s e_j, solved 256 at a time by one multi-right-hand-side
  set-up       solve of the factors (petsc.solve_columns; on a mirror-symmetric region the orbits'
               representatives' only, ``columns.estimated_solved_columns``): a column costs r_mms times one BEM step
               solve (bem.cost.bem_solve_seconds, the BEM model's solve) and, implicit, r_mms times
               one solve with D (t_fs; the representatives' only where the structure mirrors too,
               ``columns.estimated_fem_solved_columns``); plus the bonded interface system's LU (2/3 (3 n_I)^3 flops,
               replicated) at r_cpl flop/s. On a region around the interface (coupling/columns.py,
               N_Z of the N soil nodes, ``estimated_region_nodes``) the BEM solve is the model's for N_Z
               nodes and the region's LU (c_fac N_Z^1.5) is added. (Until 2026-11-29 it also priced 3 n_I products with Z's
               local rows, which the set-up does not make: 45 s of the uniform 72 m building's 68 s.)
  per step     n_fs solves with D (2: predictor and corrector), the dense interface products
               (Z's local rows: 2 (3 N_Z / p) m_Z flops, m_Z = 3 n_I, or the solved columns where the others
               are mirror images: the step reads those alone, ``columns.MirroredZ``; and, implicit, D^-1 T^T's: 2 (n_fem / p)
               m_D, m_D likewise where the structure mirrors too); M3 and Z_II: 2 (3 n_I)^2 each, replicated) at r_cpl flop/s, the step's BEM
               residual (a product with the step matrix, and H_s's kept interface columns times the
               interface change: part of c_cstep), the contact law and
               the step's bookkeeping c_cstep
  memory       the interface matrices (``interface_bytes``) and the structure's measured growth
               times the ranks

with n_I the interface nodes, N the soil nodes and N_Z those of Z's rows (N, or the region's). The constants r_cpl and c_cstep
are ``FALLBACK``'s unless ``estimate_constants.json``'s constants carry them (none of its fits does): fitted by
`python jobscripts/coupled_fit.py LOGS` to the coupling's seconds a step (SSI_FEM_Step + SSI_Contact, less the two
solves with D at each run's timing) of five coupled runs on 2 ranks, 2026-12-03, the machine otherwise idle: the
paper's building on its graded 36 m soil (`today-smooth`, 12:02) and on uniform grids of 36, 72 and 108 m
(`uniform-*-smooth`, 14:10-14:18; jobscripts/building_uniform.sh), 475 interface nodes, and the 28.8 m building of
runs/seismic/site_oblique.sh (1813 interface nodes, 14:44): -20 % to +18 % of each (the values before, 2e9 and 4 ms,
never fitted: +36 % to +112 %). The structure's solve t_fs is timed on the estimate's own ranks (one, from the
command line) and used at every rank count: the 28.8 m building's 22-32 ms on one rank against 19.2 ms in the run on
two."""
import statistics
import time

from ..sysmem import process_rss

# r_mms: a column of the multi-right-hand-side solves over one single solve (MUMPS reads the factors once a
# chunk of 256 columns; a single solve is bound by reading them). Measured on 2 ranks (-log_view, the set-up's
# SSI_BEM_Solve over its columns against the time loop's SSI_BEM_Solve a step): the paper's building, 825
# columns, 0.25 (jobscripts/building_estimate.sh); the building on the uniform 72 m grid, 1425 columns of a
# 44 649-DOF step matrix, 0.15 (jobscripts/building_uniform.sh); 0.2 between them. Before, every column was
# priced as a single solve (the uniform 72 m building's interface set-up: 155 s predicted, 21-27 s measured).
FALLBACK = {"r_cpl": 4.34e9, "c_cstep": 1.45e-3, "n_fs": 2, "r_mms": 0.2}


class CoupledCounts:
    """Collective: the structure's measured costs and the interface's counts of a coupled run
    (from ``build_coupled``'s (prob, model, iface, integrator); assembles and factorises the structure,
    nothing of the soil)."""

    def __init__(self, cfg, comm, prob, model, iface, integrator, n_solves=5):
        from ..fem.integrators import make_model_integrator
        mpi = comm.tompi4py()
        self.nI, self.N, self.steps = iface.n, prob.mesh.n_nodes, prob.n_steps
        from .columns import estimated_region_nodes, estimated_solved_columns, estimated_fem_solved_columns
        self.NZ = estimated_region_nodes(cfg, prob, iface.be_nodes)     # Z's rows: the region's nodes
        self.n_solved = estimated_solved_columns(cfg, prob, iface.be_nodes)   # (the others: mirror images)
        self.implicit = cfg.coupling == "implicit"
        self.n_fem_solved = (estimated_fem_solved_columns(cfg, prob, iface.be_nodes, model, comm) if self.implicit
                             else 3 * self.nI)
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
        col_s, fac_s = bem_solve_s, 0.0
        if self.NZ < self.N and "c_sol_nlogn" in k:      # the columns on the region: its own LU and solves
            from ..bem.cost import bem_solve_seconds
            col_s, fac_s = bem_solve_seconds(k, self.NZ, p), k.get("c_fac", 0.0) * self.NZ ** 1.5
        setup = self.fem_setup_s + fac_s + k["r_mms"] * (self.n_solved * col_s
                                                         + (self.n_fem_solved * self.fem_solve_s if self.implicit else 0.0)) \
            + 2.0 / 3.0 * n ** 3 / k["r_cpl"]
        per_step = step_seconds(c, self.nI, self.NZ, p, self.fem_solve_s, self.n_fem if self.implicit else 0,
                                self.n_solved, self.n_fem_solved)
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


def step_seconds(c, n_i, n_soil, p, fem_solve_s, n_fem=0, n_zcols=None, n_dcols=None):
    """Seconds the coupling adds to each step on p ranks (module docstring, 'per step'): n_fs solves with
    D, the dense interface products at r_cpl flop/s (Z's local rows, ``n_zcols`` of its columns kept, 3 n_i
    by default: on a mirror-symmetric region the representatives', ``columns.MirroredZ``, whose one pass
    over them serves every image; ``n_fem`` > 0, the implicit step: D^-1 T^T's, ``n_dcols`` of its columns
    kept likewise) and c_cstep; ``c``: the
    constants (FALLBACK where they have none). ``petsc-ssi estimate`` and the coupled run's own prediction
    both use it."""
    k = dict(FALLBACK)
    k.update(c or {})
    n = 3 * n_i
    nz = n if n_zcols is None else n_zcols
    nd = n if n_dcols is None else n_dcols
    flops = 2.0 * (3.0 * n_soil / p) * nz + 2.0 * (n_fem / p) * nd
    return k["n_fs"] * fem_solve_s + (flops + 4.0 * n * n) / k["r_cpl"] + k["c_cstep"]


def describe(cc):
    """One line of what the coupling's counts are."""
    n = 3 * cc.nI
    nf = getattr(cc, "n_fem_solved", n) if cc.implicit else cc.n_solved
    solved = ("" if cc.n_solved == n and nf == n else
              f", {cc.n_solved} solved, the others mirror images" if nf == cc.n_solved else
              f", {cc.n_solved} soil and {nf} structure columns solved, the others mirror images")
    return (f"[ssi]   coupling: {cc.nI} interface nodes ({3 * cc.nI} columns{solved}), structure {cc.n_fem} dofs: "
            f"factorised in {cc.fem_setup_s:.3g} s, a solve {cc.fem_solve_s * 1e3:.3g} ms (measured on "
            f"{cc.ranks_measured} rank(s)), {'implicit' if cc.implicit else 'staggered'} coupling")

