"""A load on the structure's nodes as a source: f(t) = F a(t), with F the consistent nodal forces of
the options' pressures and point loads (``fem.loads``) in the dof layout [N, N m] and a(t) a scalar
history (``petsc_ssi.histories``).

The integrators take a load sample per step, by one of two rules (``fem/integrators.py``):
  'cell'  the mean of a over [t_n - dt/2, t_n + dt/2] (n = 0: [0, dt/2]): the load at t_n of the
          Green scheme and of Newmark;
  'step'  the mean of a over (t_{n-1}, t_n]: the midpoint form of the implicit coupling.
Both are exact for every history kind (``History.cell_mean``, ``History.step_mean``).
"""


class NodalLoad:
    """F a(t) (module docstring); ``F`` a PETSc Vec in the dof layout, ``history`` a ``History``."""

    def __init__(self, F, history, name="-ssi_fem_load_*"):
        self.F, self.history, self.name = F, history, name

    def factor(self, n, dt, rule="cell"):
        """The history's sample of step n (``rule`` 'cell' or 'step')."""
        if rule == "cell":
            return self.history.cell_mean(n, dt)
        if rule == "step":
            return self.history.step_mean(n, dt)
        raise ValueError(f"NodalLoad: unknown sampling rule {rule!r} (cell or step)")

    def sample(self, out, n, dt, rule="cell", add=False):
        """Collective: F times the sample of step n into ``out`` (``add``: added to it)."""
        c = self.factor(n, dt, rule)
        if add:
            out.axpy(c, self.F)
        else:
            self.F.copy(out)
            out.scale(c)
        return out
