r"""Time integrators of M a + C v + K u = f with Rayleigh damping C = alpha_m M + a1 K (lumped M;
alpha_m is Rayleigh's a0).

GreenIntegrator: implicit Green's functions (Soares & Mansur 2005; paper
Section 3, eqs. 13-24). NewmarkIntegrator: plain Newmark, for comparison.
Both factorise D = M/(alpha dt^2) + delta/(alpha dt) C + K (eq. 15) once.

Derivation of the constants (alpha, delta = Newmark's beta, gamma).
The implicit Green's function G(t) is the displacement response to
u(0) = 0, v(0) = M^{-1} (a unit impulse), computed by ONE Newmark step; then
a(0) = -M^{-1} C M^{-1} = -alpha_m M^{-1} and Newmark's step gives

  G(dt)   = b1 D^{-1},        b1 = (delta/alpha - 1) alpha_m
                                   - (dt/2)(delta/alpha - 2) alpha_m^2 - b0
  dG(dt)  = b3 D^{-1} + b2 M^{-1},   b3 = delta b1 / (alpha dt),
                                   b2 = 1 - dt (1 - delta) alpha_m + delta dt b0
  ddG(dt) = b1/(alpha dt^2) D^{-1} + b0 M^{-1},
                                   b0 = (1/(2 alpha) - 1) alpha_m - 1/(alpha dt)

(the velocity/acceleration follow Newmark's updates a1 = (u1 - dt v0)/(alpha
dt^2) - (1/(2 alpha) - 1) a0, v1 = v0 + dt((1 - delta) a0 + delta a1)). The
free response to (u, v) at t_{n-1} is u(t) = [dG M + G C] u + G M v, so with
C = alpha_m M

  u^n = D^{-1} M (b4 u^{n-1} + b1 v^{n-1}) + b2 u^{n-1},         b4 = alpha_m b1 + b3   (13)
  v^n = D^{-1} M (b5 u^{n-1} + b3 v^{n-1}) + b6 u^{n-1} + b2 v^{n-1},
                                     b5 = alpha_m b3 + b1/(alpha dt^2), b6 = alpha_m b2 + b0

and since b3/b1 = delta/(alpha dt), (b3/b1) b4 = b5 exactly when delta^2 = alpha:
then the velocity reuses the same solve, v^n = b7 w + b6 u + b2 v with
w = D^{-1} M (b4 u + b1 v), b7 = b3/b1 (eq. 14). These are the printed
eqs. 17-24; no typo in them (the text calls delta "beta" once). Only the
trapezoidal rule alpha = 1/4, delta = 1/2 makes the scheme identical to
Newmark in free vibration (b2 = -1, b4 = b1 (alpha_m + 2/dt), b1 = 4/dt:
u^n = 2 D^{-1}M(...) - u, v^n = 2(u^n - u^{n-1})/dt - v^{n-1}); for other
delta^2 = alpha it is a different (Green-superposed) scheme.

Loads. The load enters as a velocity impulse at t_n (eq. 16):
v^n <- v^n + M^{-1} f^n dt, so u^n does not depend on f^n (B.1 before B.5).
The impulse train sum_k M^{-1} f^k dt delta(t - t_k) approximates the Duhamel
integral by a rectangle rule; comparing with the trapezoidal rule shows
  (i) an O(dt) displacement error -dt/2 G(t_n) f(0) unless the load at t = 0
      enters as a HALF impulse M^{-1} f(0+) dt/2 (``start(f0=...)``), and
 (ii) the state velocity after the impulse exceeds v(t_n) by M^{-1} f^n dt/2:
      v(t_n) is the mean of the velocities just before and just after the
      impulse (``velocity()``).
With both, and with f^n the mean of f over [t_n - dt/2, t_n + dt/2] (equal
to f(t_n) + O(dt^2) for smooth loads), displacement and velocity converge at
order 2, like Newmark's; across a jump of the load the displacement stays
second order, while at the one node next to the jump the velocity has an O(dt)
local error (a nodal sample cannot tell where in the step the load stops;
Newmark has the same). So f^n is "the load at t_n", sampled as that cell mean.
Taking f^n = f(t_n) for a load switched on at t = 0 without the half impulse
gives order 1 (tests/fem/test_fem_convergence.py shows both).

Interface forces (for the FEM-BEM coupling). ``correct(f, f_interface)``
takes f_interface^n in the same sense as f^n: THE LOAD AT t_n, i.e. the cell
mean over [t_n - dt/2, t_n + dt/2]. A BE traction is piecewise constant on
(t_{n-1}, t_n]: its value p^n is the mean over that interval, centred at
t_n - dt/2, so handing p^n over as it is puts the impulse half a step late
and the scheme drops to order 1. Extrapolate it to the cell:
    f_interface^n = 1.5 p^n - 0.5 p^{n-1}      (p^0 = 0: at rest before t = 0)
(= (p^n + p^{n+1})/2 with p^{n+1} extrapolated linearly, = f(t_n) + O(dt^2)
for smooth tractions), which keeps order 2. On an SDOF under f = sin(5 t) the
observed displacement orders are 1.07 (p^n as it is) and 2.02 (extrapolated)
(test_interface_traction_must_be_extrapolated, tests/fem/test_fem_convergence.py).
The velocity at t_n needs the impulse of step n: between ``predict()`` and
``correct()`` only ``free_velocity()`` (v(t_n-), before the impulse) is
defined, and ``velocity()`` raises.

Relation to Newmark's treatment of loads. Trapezoidal Newmark is the
trapezoidal (Crank-Nicolson) rule on y' = A y + J f, y = (u, v):
(I - dt/2 A) y^n = (I + dt/2 A) y^{n-1} + dt/2 J (f^{n-1} + f^n), so its u^n
depends on f^n. With P = (I - dt/2 A)^{-1} dt/2, the shifted state
z^n = y^n - P J f^n obeys z^n = R z^{n-1} + dt (I - dt/2 A)^{-2} J f^{n-1}, R the
free propagator; as (I - dt/2 A)^{-2} = R + O(dt^2), that is the Green
recurrence (impulse dt J f^{n-1} at t_{n-1}, then one free step) to O(dt^3) per
step, and y^n = z^n + P J f^n is the Green state before the impulse at t_n plus
half of it: Newmark's velocity is the mean velocity of ``velocity()``, and
Newmark's u^n holds an extra O(dt^2) part of f^n (the displacement part of
P J f^n) that the Green scheme drops, which is what makes u^n independent of
f^n. Both are second order; they agree exactly only in free vibration.

Newmark with loads (NewmarkIntegrator): the usual form with the same cell-mean
samples f^n, a^0 = M^{-1}(f^0 - C v^0 - K u^0).

Stiffness-proportional damping (a1 > 0, issue 43). D = (1 + a1 delta/(alpha dt)) K
+ (1/(alpha dt^2) + delta alpha_m/(alpha dt)) M is still factorised once (K scaled, the same
sparsity). Newmark adds a1 K (delta/(alpha dt) u + (delta/alpha - 1) v + dt (delta/(2 alpha) - 1) a)
to its right-hand side (one product with K per step) and a^0 = M^{-1}(f^0 - C v^0 - K u^0). The
midpoint form: D u^n = (4M/dt^2 + 2C/dt - K) u^{n-1} + (4/dt) M v^{n-1} + 2 fbar^n, i.e. its K u^{n-1}
term (already formed) gets the factor (2 a1/dt - 1). The Green scheme with a1 > 0 is taken for the
trapezoidal rule only (alpha 1/4, delta 1/2), where its free step IS the trapezoidal free step (above):
with kappa = 2 a1/dt, c = 4/dt^2 + 2 alpha_m/dt and D = (1 + kappa) K + c M,
    K u = (D u - c M u)/(1 + kappa),   so   D^{-1}[(c M + (kappa - 1) K) u + (4/dt) M v]
        = r u + D^{-1} M (c (1 - r) u + (4/dt) v),   r = (kappa - 1)/(kappa + 1),
which is eq. 13's form u^n = D^{-1} M (b4 u + b1 v) + b2 u with b2 = r, b4 = c (1 - r), b1 = 4/dt, and
v^n = 2 (u^n - u^{n-1})/dt - v^{n-1} = b7 w + b6 u + bv v with b7 = 2/dt, b6 = 2 (r - 1)/dt, bv = -1
(kappa = 0: r = -1, the constants above; bv = b2 in general without a1). The cost is nil: the same
one solve with D per step, no product with K (the K term is folded into D and r). Other Green
constants (delta^2 = alpha != 1/4) with a1 > 0 are refused with the options (-ssi_fem_integrator newmark
takes them).

Constraints: fixed dofs have zero rows and columns in D (the mean diagonal on
the diagonal, ``assembly.eliminate_dofs``) and are masked in every impulse
and right-hand side, so u = v = 0 stays exact there. A load on a fixed dof is
therefore taken by the support and does nothing: the first time a load (or
interface force) has a non-zero entry on a fixed dof, rank 0 prints a
warning, once per integrator.
"""
import numpy as np

from ..petsc import init, SSIError, check, collective_error, set_default_options, \
    direct_solver_defaults, printf, warn, check_reproducible_solver
from ..monitor import event
from .assembly import check_mass, owned_dofs, eliminate_dofs
from .options import damping


def green_constants(dt, alpha_m=0.0, alpha=0.25, delta=0.5, a1=0.0):
    """b0..b7 of paper eqs. 17-24 (derived in the module docstring) and bv, the velocity's own factor
    in v^n = b7 w + b6 u + bv v (= b2 without stiffness-proportional damping); with a1 > 0 (trapezoidal
    only) the constants of the trapezoidal free step with C = alpha_m M + a1 K (module docstring)."""
    if a1:
        if abs(alpha - 0.25) > 1e-12 or abs(delta - 0.5) > 1e-12:
            raise SSIError(f"the Green's-function integrator takes stiffness-proportional damping (a1 = {a1:g} s) "
                           f"with the trapezoidal rule only (alpha 1/4, delta 1/2; got {alpha:g}, {delta:g}); "
                           "-ssi_fem_integrator newmark takes any")
        kappa = 2.0 * a1 / dt
        c = 4.0 / dt ** 2 + 2.0 * alpha_m / dt
        r = (kappa - 1.0) / (kappa + 1.0)
        return dict(b1=4.0 / dt, b2=r, b4=c * (1.0 - r), b6=2.0 * (r - 1.0) / dt, b7=2.0 / dt, bv=-1.0, a1=a1)
    b0 = (1 / (2 * alpha) - 1) * alpha_m - 1 / (alpha * dt)
    b1 = (delta / alpha - 1) * alpha_m - 0.5 * dt * (delta / alpha - 2) * alpha_m ** 2 - b0
    b2 = 1 - dt * (1 - delta) * alpha_m + delta * dt * b0
    b3 = delta * b1 / (alpha * dt)
    b4 = alpha_m * b1 + b3
    b5 = alpha_m * b3 + b1 / (alpha * dt ** 2)
    b6 = alpha_m * b2 + b0
    b7 = b3 / b1
    return dict(b0=b0, b1=b1, b2=b2, b3=b3, b4=b4, b5=b5, b6=b6, b7=b7, bv=b2)


def d_mass_coefficient(dt, alpha_m, alpha, delta):
    """c with D = k K + c M (eq. 15 with C = alpha_m M + a1 K)."""
    return 1.0 / (alpha * dt ** 2) + delta * alpha_m / (alpha * dt)


def d_stiffness_coefficient(dt, a1, alpha, delta):
    """k with D = k K + c M (eq. 15 with C = alpha_m M + a1 K): 1 + a1 delta/(alpha dt)."""
    return 1.0 + delta * a1 / (alpha * dt)


# CG + BoomerAMG with the settings hypre's documentation advises for 3D elasticity
# (strong threshold 0.5 in 3D, HMIS coarsening, ext+i interpolation, one level of
# aggressive coarsening); not compared with hypre's defaults here. On the meshes of
# runs/foundation/README.md MUMPS (factorise once) is the faster solver anyway.
# Tight rtol: the Green's-function scheme assumes exact solves of D.
SOLVER_ITERATIVE = {"ksp_type": "cg", "ksp_rtol": "1e-12", "ksp_atol": "1e-50",
                    "pc_type": "hypre", "pc_hypre_type": "boomeramg",
                    "pc_hypre_boomeramg_strong_threshold": "0.5",
                    "pc_hypre_boomeramg_coarsen_type": "HMIS",
                    "pc_hypre_boomeramg_interp_type": "ext+i",
                    "pc_hypre_boomeramg_agg_nl": "1"}


def make_solver(A, prefix, solver, comm, coords_vec=None, log=printf, near_null=None):
    """Collective: KSP on A with prefix; defaults only where the user set none.

    The AMG near-null space: ``near_null`` (a PETSc NullSpace: the dof map's six
    rigid-body modes, rotation dofs included), or PETSc's rigid-body modes of the
    coordinates ``coords_vec`` (a translations-only layout, bs 3).
    A Krylov method starts from the previous solution (the step-to-step
    change is small); preonly (LU) ignores it.
    """
    PETSc = init()
    defaults = direct_solver_defaults(comm) if solver == "direct" else dict(SOLVER_ITERATIVE)
    set_default_options(prefix, defaults, log=log)
    check_reproducible_solver(prefix, comm, "the structure")
    if near_null is not None:
        A.setNearNullSpace(near_null)
    elif coords_vec is not None:
        A.setNearNullSpace(PETSc.NullSpace().createRigidBody(coords_vec))
    ksp = PETSc.KSP().create(comm)
    ksp.setOptionsPrefix(prefix)
    ksp.setOperators(A)
    ksp.setFromOptions()
    if ksp.getType() != "preonly":
        ksp.setInitialGuessNonzero(True)
    return ksp


def setup_or_fail(ksp, probe, what, comm):
    """Collective: factorise (KSP setUp) and solve ``probe``; SSIError on failure."""
    PETSc = init()
    err = None
    try:
        ksp.setUp()
        x = probe.duplicate()
        x.zeroEntries()
        ksp.solve(probe, x)
        reason = ksp.getConvergedReason()
        if reason < 0 or not np.isfinite(x.norm()):
            err = f"the solve with {what} failed (KSP reason {reason}): the matrix is singular or indefinite"
    except PETSc.Error as exc:
        err = f"factorising {what} failed ({str(exc).splitlines()[0]}): the matrix is singular"
    collective_error(err, comm)


def count_on_fixed(forces, owned, comm):
    """Collective: number of non-zero entries of the Vecs ``forces`` (None skipped) on the
    fixed dofs ``owned`` (global, owned by this rank), summed over the ranks. Entries below
    1e-12 of the force's largest entry are round-off (e.g. the in-plane part of a pressure
    on a symmetry plane) and not counted."""
    n = 0
    for f in forces:
        if f is None:
            continue
        tiny = 1e-12 * f.norm(init().NormType.NORM_INFINITY)      # collective: on every rank
        if len(owned):
            r0 = f.getOwnershipRange()[0]
            n += int(np.count_nonzero(np.abs(f.getArray(readonly=True)[owned - r0]) > tiny))
    return comm.tompi4py().allreduce(n)


def fixed_load_message(count, where):
    return (f"a load acts on {count} fixed dof(s) {where}: the supports take it and it does not move the "
            "structure (-ssi_fem_fixed); warned once")


class _Dynamic:
    """Shared set-up: D = k K + c M, the mask of free dofs, M^{-1} on free dofs. C = alpha_m M + a1 K."""

    def __init__(self, K, m, dt, alpha_m=0.0, fixed=(), alpha=0.25, delta=0.5,
                 prefix="ssi_fem_", solver="direct", coords_vec=None, log=printf, near_null=None, a1=0.0,
                 modal=None):
        comm = K.getComm()
        check(dt > 0, f"time step dt = {dt} must be > 0", comm)
        check(a1 >= 0 and alpha_m >= 0, f"damping C = a0 M + a1 K needs a0, a1 >= 0 (got {alpha_m:g}, {a1:g})", comm)
        self.comm, self.K, self.m, self.dt = comm, K, m, float(dt)
        self.alpha_m, self.alpha, self.delta = float(alpha_m), float(alpha), float(delta)
        self.a1 = float(a1)
        self._masks(fixed)
        check_mass(m, self.mask, comm)
        with event("FEM_assembly"):
            self.D = self._assemble_D()
        self.ksp = make_solver(self.D, prefix, solver, comm, coords_vec, log, near_null)
        with event("FEM_factor"):
            setup_or_fail(self.ksp, self.mask, "D (eq. 15)", comm)
        # modal damping (fem/modal_damping.py): D = D0 + delta/(alpha dt) C_modal, solved by Woodbury
        self.modal = modal if modal is not None and modal.active else None
        if self.modal is not None:
            with event("FEM_factor"):
                self.modal.bind(self._solve0, self.delta / (self.alpha * self.dt), self.mask)
        self.u, self.v, self.w, self.rhs = (self._zeros() for _ in range(4))
        self.n = 0
        self.fixed_load_warning = None       # the warning, once a load acted on fixed dofs

    # ------------------------------------------------------------ checkpoint
    def checkpoint_vecs(self, prefix="fem_"):
        """{name: Vec} of the state the next step needs (``io.checkpoint``)."""
        return {prefix + k: getattr(self, a) for k, a in self._STATE}

    def checkpoint_scalars(self, prefix="fem_"):
        return {prefix + "n": self.n, prefix + "warned": int(self.fixed_load_warning is not None)}

    def restore(self, reader, prefix="fem_"):
        """Collective: the state of a checkpoint (``checkpoint_vecs``, ``checkpoint_scalars``)."""
        for k, a in self._STATE:
            reader.load(prefix + k, getattr(self, a))
        s = reader.serial
        self.n = int(s[prefix + "n"])
        if int(s[prefix + "warned"]):
            self.fixed_load_warning = "(warned before the restart)"

    _STATE = (("u", "u"), ("v", "v"))

    def _zeros(self):
        v = self.m.duplicate()
        v.zeroEntries()
        return v

    def _masks(self, fixed):
        """Owned fixed dofs, the 0/1 mask of free dofs and M^{-1} on free dofs."""
        r0 = self.K.getOwnershipRange()[0]
        self.any_fixed = len(fixed) > 0               # ``fixed`` is replicated: the same on every rank
        self.fixed_owned = owned_dofs(fixed, self.K)
        self.mask = self.m.duplicate()
        self.mask.set(1.0)
        self.mask.getArray()[self.fixed_owned - r0] = 0.0
        mm = self.m.getArray(readonly=True)
        self.minv = self.m.duplicate()
        self.minv.getArray()[:] = self.mask.getArray(readonly=True) / np.where(mm > 0, mm, 1.0)

    def _assemble_D(self):
        """Collective: D = (1 + delta a1/(alpha dt)) K + (1/(alpha dt^2) + delta alpha_m/(alpha dt)) M
        (eq. 15), fixed dofs eliminated (``assembly.eliminate_dofs``)."""
        PETSc = init()
        D = self.K.copy()
        if self.a1:
            D.scale(d_stiffness_coefficient(self.dt, self.a1, self.alpha, self.delta))
        cm = self.m.copy()
        cm.scale(d_mass_coefficient(self.dt, self.alpha_m, self.alpha, self.delta))
        D.setDiagonal(cm, addv=PETSc.InsertMode.ADD_VALUES)
        cm.destroy()
        return eliminate_dofs(D, self.fixed_owned)

    @property
    def t(self):
        return self.n * self.dt

    def _set_initial(self, u0, v0):
        for dst, src in ((self.u, u0), (self.v, v0)):
            if src is None:
                dst.zeroEntries()
            else:
                src.copy(dst)
            dst.pointwiseMult(dst, self.mask)
        self.n = 0

    def _check_fixed(self, *forces):
        """Collective: warn (rank 0, once) if a force has a non-zero entry on a fixed dof
        (one small allreduce per call until then; none without fixed dofs)."""
        if self.fixed_load_warning is not None or not self.any_fixed:
            return
        count = count_on_fixed(forces, self.fixed_owned, self.comm)
        if count:
            self.fixed_load_warning = fixed_load_message(count, f"at step {self.n} (t = {self.t:.6g} s)")
            warn(self.fixed_load_warning, self.comm)

    def _masked_minv(self, out, *forces):
        """Collective: out = M^{-1} (sum of forces) on free dofs, 0 on fixed ones (where a
        non-zero force is dropped, with a warning the first time)."""
        self._check_fixed(*forces)
        out.zeroEntries()
        for f in forces:
            if f is not None:
                out.axpy(1.0, f)
        out.pointwiseMult(out, self.minv)
        return out

    def _solve0(self, b, x):
        """The solve with the factorised D (without the modal part)."""
        self.ksp.solve(b, x)
        if self.ksp.getConvergedReason() < 0:
            raise SSIError(f"solve with D diverged at step {getattr(self, 'n', 0)} (KSP reason "
                           f"{self.ksp.getConvergedReason()})")

    def solve(self, b, x):
        """x = D^{-1} b (with modal damping: the factorised part, then the Woodbury correction)."""
        self._solve0(b, x)
        self.complete_solve(x)

    def complete_solve(self, x):
        """Collective: a solution of the factorised D (e.g. a column of ``petsc.solve_columns`` on
        ``self.ksp``) made a solution of D: the modal damping's correction (none without it)."""
        if self.modal is not None:
            self.modal.correct(x)
        return x

    def _add_modal(self, rhs, x, scale):
        """rhs += scale C_modal x (nothing without modal damping)."""
        if self.modal is not None:
            self.modal.mult_add(x, rhs, scale)

    def destroy(self):
        for obj in (self.ksp, self.D, self.u, self.v, self.w, self.rhs, self.mask, self.minv):
            obj.destroy()
        if self.modal is not None:
            self.modal.destroy()


class GreenIntegrator(_Dynamic):
    """Implicit Green's-function integrator, paper eqs. 13-16 (trapezoidal).

    Collective. Per step: ``predict()`` -> u^n (Table 2, B.1, eq. 13, one
    triangular solve), then ``correct(f, f_interface)`` -> v^n (B.5-B.6,
    eqs. 14 and 16). ``step(f)`` does both. f and f_interface are the loads
    at t_n as cell means over [t_n - dt/2, t_n + dt/2] (module docstring; a
    BE traction piecewise constant on (t_{n-1}, t_n] must be extrapolated).
    Between predict() and correct() ``velocity()`` raises (v(t_n) needs the
    impulse of step n); ``free_velocity()`` is v(t_n-) at any time.
    """

    def __init__(self, K, m, dt, alpha_m=0.0, fixed=(), alpha=0.25, delta=0.5, **kw):
        check(abs(delta * delta - alpha) < 1e-12, f"Green's-function integrator needs delta^2 = alpha "
              f"(paper eq. 24); got alpha {alpha}, delta {delta}", K.getComm())
        a1 = float(kw.get("a1", 0.0))
        check(not a1 or (abs(alpha - 0.25) < 1e-12 and abs(delta - 0.5) < 1e-12),
              f"the Green's-function integrator takes stiffness-proportional damping (a1 = {a1:g} s) with the "
              f"trapezoidal rule only (alpha 1/4, delta 1/2; got {alpha:g}, {delta:g}); -ssi_fem_integrator "
              "newmark takes any", K.getComm())
        check(kw.get("modal") is None or (abs(alpha - 0.25) < 1e-12 and abs(delta - 0.5) < 1e-12),
              f"the Green's-function integrator takes modal damping with the trapezoidal rule only (alpha 1/4, "
              f"delta 1/2; got {alpha:g}, {delta:g}); -ssi_fem_integrator newmark takes any", K.getComm())
        super().__init__(K, m, dt, alpha_m, fixed, alpha, delta, **kw)
        self.b = green_constants(dt, alpha_m, alpha, delta, self.a1)
        self.vhalf = m.duplicate()            # M^{-1} f dt/2 of the last impulse
        self.vhalf.zeroEntries()
        self._predicted = False
        self._kick = 1.0                      # v = v(t_n-) + kick * vhalf (1 after start, 2 after correct)

    _STATE = (("u", "u"), ("v", "v"), ("vhalf", "vhalf"))

    def checkpoint_scalars(self, prefix="fem_"):
        return dict(super().checkpoint_scalars(prefix), **{prefix + "kick": self._kick})

    def restore(self, reader, prefix="fem_"):
        super().restore(reader, prefix)
        self._kick = float(reader.serial[prefix + "kick"])
        self._predicted = False

    def start(self, u0=None, v0=None, f0=None):
        """Initial state; f0 = mean load over [0, dt/2] enters as a half impulse."""
        self._set_initial(u0, v0)
        self._masked_minv(self.vhalf, f0)
        self.vhalf.scale(0.5 * self.dt)
        self.v.axpy(1.0, self.vhalf)
        self._predicted = False
        self._kick = 1.0

    def predict(self):
        """u^n from (u^{n-1}, v^{n-1}) (eq. 13); v holds the free velocity v(t_n-) after."""
        if self._predicted:
            raise SSIError("GreenIntegrator.predict() called twice without correct()")
        b = self.b
        self.u.copy(self.rhs)
        self.rhs.scale(b["b4"])
        self.rhs.axpy(b["b1"], self.v)
        self.rhs.pointwiseMult(self.rhs, self.m)
        self._add_modal(self.rhs, self.u, 2.0 * (1.0 - b["b2"]) / self.dt)   # trapezoidal: (2/dt)(1 - b2) C_modal u
        self.rhs.pointwiseMult(self.rhs, self.mask)
        self.solve(self.rhs, self.w)                              # w = D^-1 M (b4 u + b1 v)
        self.v.scale(b["bv"])                                     # eq. 14 without f* (bv = b2 without a1)
        self.v.axpy(b["b6"], self.u)
        self.v.axpy(b["b7"], self.w)
        self.u.scale(b["b2"])                                     # eq. 13
        self.u.axpy(1.0, self.w)
        self.n += 1
        self._predicted = True
        return self.u

    def correct(self, f=None, f_interface=None):
        """Add the impulse M^{-1} (f^n + f_f^n) dt to the velocity (B.5, eq. 16)."""
        if not self._predicted:
            raise SSIError("GreenIntegrator.correct() called without predict()")
        self._masked_minv(self.vhalf, f, f_interface)
        self.vhalf.scale(0.5 * self.dt)
        self.v.axpy(2.0, self.vhalf)
        self._predicted = False
        self._kick = 2.0
        return self.v

    def step(self, f=None):
        self.predict()
        return self.correct(f)

    def velocity(self, out=None):
        """v(t_n): mean of the velocities before and after the impulse at t_n
        (at t = 0 the state before the initial half impulse). SSIError between
        predict() and correct(): the impulse of step n is not known yet."""
        if self._predicted:
            raise SSIError(f"GreenIntegrator.velocity() called between predict() and correct() of step "
                           f"{self.n}: v(t_n) needs the load of step n; call correct() first, or use "
                           "free_velocity() for the velocity before the impulse")
        out = self.v.duplicate() if out is None else out
        self.v.copy(out)
        out.axpy(-1.0, self.vhalf)
        return out

    def free_velocity(self, out=None):
        """v(t_n-): the velocity just before the impulse at t_n (the free response of
        the state at t_{n-1}), defined before and after correct(); v0 at t = 0."""
        out = self.v.duplicate() if out is None else out
        self.v.copy(out)
        if not self._predicted:
            out.axpy(-self._kick, self.vhalf)
        return out


class NewmarkIntegrator(_Dynamic):
    """Plain Newmark (trapezoidal by default) with the same interface: step(f)."""

    def __init__(self, K, m, dt, alpha_m=0.0, fixed=(), alpha=0.25, delta=0.5, **kw):
        super().__init__(K, m, dt, alpha_m, fixed, alpha, delta, **kw)
        self.a = m.duplicate()
        a, d, am = self.alpha, self.delta, self.alpha_m
        self.c_u = 1 / (a * dt ** 2) + am * d / (a * dt)
        self.c_v = 1 / (a * dt) + am * (d / a - 1)
        self.c_a = (1 / (2 * a) - 1) + am * dt * (d / (2 * a) - 1)
        # the stiffness-proportional part a1 K (d/(a dt) u + (d/a - 1) v + dt (d/(2a) - 1) a)
        self.k_u, self.k_v, self.k_a = d / (a * dt), d / a - 1, dt * (d / (2 * a) - 1)
        self.kx = (m.duplicate(), m.duplicate()) if self.a1 else None      # (work, K work) with a1 > 0

    _STATE = (("u", "u"), ("v", "v"), ("a", "a"))

    def start(self, u0=None, v0=None, f0=None):
        """Initial state; a^0 = M^{-1}(f^0 - C v^0 - K u^0) on free dofs."""
        self._set_initial(u0, v0)
        self._check_fixed(f0)
        self.K.mult(self.u, self.w)
        self.w.scale(-1.0)
        if f0 is not None:
            self.w.axpy(1.0, f0)
        if self.a1:                                               # - a1 K v^0
            self.K.mult(self.v, self.rhs)
            self.w.axpy(-self.a1, self.rhs)
        self._add_modal(self.w, self.v, -1.0)                     # - C_modal v^0
        self.w.pointwiseMult(self.w, self.minv)
        self.w.axpy(-self.alpha_m, self.v)
        self.w.pointwiseMult(self.w, self.mask)
        self.w.copy(self.a)

    def step(self, f=None):
        self.predict(f)
        return self.complete()

    def predict(self, f=None):
        """u^n for the load f (without further forces) into ``self.w``; ``complete(du)``
        then adds a displacement D^{-1} g of further forces g of the same step
        (the FEM-BEM coupling's interface force) and finishes the step."""
        self._check_fixed(f)
        self.rhs.zeroEntries()
        self.rhs.axpy(self.c_u, self.u)
        self.rhs.axpy(self.c_v, self.v)
        self.rhs.axpy(self.c_a, self.a)
        self.rhs.pointwiseMult(self.rhs, self.m)
        if self.a1:                                               # + a1 K (k_u u + k_v v + k_a a)
            kx, kk = self.kx
            kx.zeroEntries()
            kx.axpy(self.k_u, self.u)
            kx.axpy(self.k_v, self.v)
            kx.axpy(self.k_a, self.a)
            self.K.mult(kx, kk)
            self.rhs.axpy(self.a1, kk)
        if self.modal is not None:                                # + C_modal (k_u u + k_v v + k_a a)
            mw = self.modal.work
            mw.zeroEntries()
            mw.axpy(self.k_u, self.u)
            mw.axpy(self.k_v, self.v)
            mw.axpy(self.k_a, self.a)
            self.modal.mult_add(mw, self.rhs)
        if f is not None:
            self.rhs.axpy(1.0, f)
        self.rhs.pointwiseMult(self.rhs, self.mask)
        self.solve(self.rhs, self.w)                              # u^n
        return self.w

    def complete(self, du=None):
        a, d, dt = self.alpha, self.delta, self.dt
        if du is not None:
            self.w.axpy(1.0, du)
        # a^n = (u^n - u - dt v)/(a dt^2) - (1/(2a) - 1) a^{n-1}
        self.rhs.waxpy(-1.0, self.u, self.w)
        self.rhs.axpy(-dt, self.v)
        self.rhs.scale(1 / (a * dt ** 2))
        self.rhs.axpy(-(1 / (2 * a) - 1), self.a)
        self.v.axpy(dt * (1 - d), self.a)
        self.v.axpy(dt * d, self.rhs)
        self.rhs.copy(self.a)
        self.w.copy(self.u)
        self.n += 1
        return self.u

    def velocity(self, out=None):
        out = self.v.duplicate() if out is None else out
        self.v.copy(out)
        return out

    def destroy(self):
        self.a.destroy()
        for x in self.kx or ():
            x.destroy()
        super().destroy()


class MidpointIntegrator(NewmarkIntegrator):
    r"""The trapezoidal rule in its midpoint form, with the load as a mean over
    each step (the FEM-BEM coupling's structure integrator):

        M (v^n - v^{n-1})/dt + C (v^n + v^{n-1})/2 + K (u^n + u^{n-1})/2 = fbar^n,
        (u^n - u^{n-1})/dt = (v^n + v^{n-1})/2,

    fbar^n the mean load over (t_{n-1}, t_n]. This is trapezoidal Newmark
    (alpha 1/4, delta 1/2; the same D, eq. 15) with (f^{n-1} + f^n)/2 replaced
    by the interval mean, so a boundary-element traction, which IS the mean over
    (t_{n-1}, t_n] (piecewise constant in time), enters without a time shift,
    and the work it does over a step, fbar^n . (u^n - u^{n-1}), is the work the
    soil receives in the BEM's own time basis (piecewise-linear u, constant p):
    the discrete energy exchange across the interface balances exactly.
        D u^n = (4M/dt^2 + 2C/dt - K) u^{n-1} + (4/dt) M v^{n-1} + 2 fbar^n
        v^n = 2 (u^n - u^{n-1})/dt - v^{n-1}
    ``predict(fbar)`` -> w (u^n without further forces); ``complete(du)`` with
    du = D^{-1} (2 g) for a further interval-mean force g of the same step."""

    def __init__(self, K, m, dt, alpha_m=0.0, fixed=(), alpha=0.25, delta=0.5, **kw):
        check(abs(alpha - 0.25) < 1e-12 and abs(delta - 0.5) < 1e-12,
              f"the midpoint (trapezoidal) integrator needs Newmark alpha 1/4, delta 1/2; got {alpha}, {delta}",
              K.getComm())
        super().__init__(K, m, dt, alpha_m, fixed, alpha, delta, **kw)
        self.ku = m.duplicate()

    _STATE = (("u", "u"), ("v", "v"))           # (no acceleration: the midpoint form has none)

    def start(self, u0=None, v0=None, f0=None):
        self._set_initial(u0, v0)

    def predict(self, f=None):
        dt, am = self.dt, self.alpha_m
        self._check_fixed(f)
        self.rhs.zeroEntries()
        self.rhs.axpy(4.0 / dt ** 2 + 2.0 * am / dt, self.u)
        self.rhs.axpy(4.0 / dt, self.v)
        self.rhs.pointwiseMult(self.rhs, self.m)
        self.K.mult(self.u, self.ku)
        self.rhs.axpy(2.0 * self.a1 / dt - 1.0, self.ku)          # (2C/dt - K) u: a1 K's part with -K
        self._add_modal(self.rhs, self.u, 2.0 / dt)               # and the modal part of 2C/dt u
        if f is not None:
            self.rhs.axpy(2.0, f)
        self.rhs.pointwiseMult(self.rhs, self.mask)
        self.solve(self.rhs, self.w)
        return self.w

    def complete(self, du=None):
        if du is not None:
            self.w.axpy(1.0, du)
        # v^n = 2 (u^n - u^{n-1})/dt - v^{n-1}
        self.v.scale(-1.0)
        self.v.axpy(2.0 / self.dt, self.w)
        self.v.axpy(-2.0 / self.dt, self.u)
        self.w.copy(self.u)
        self.n += 1
        return self.u

    def destroy(self):
        self.ku.destroy()
        super().destroy()


def make_integrator(kind, *args, **kw):
    """'green', 'newmark' or 'midpoint'."""
    return {"green": GreenIntegrator, "newmark": NewmarkIntegrator, "midpoint": MidpointIntegrator}[kind](*args, **kw)


def near_null_args(solver, model):
    """(coords_vec, near_null) for make_solver: none for a direct solver; PETSc's rigid-body
    modes of the coordinates for a brick-only model; the dof map's six modes otherwise."""
    if solver != "iterative":
        return None, None
    if model.dofmap.uniform3:
        return model.coords_vec(), None
    return None, model.dofmap.near_null_space(model.mesh.coords)


def make_model_integrator(cfg, comm, dt, model=None, integrator=None):
    """Collective: (model, integrator, alpha_m) for the options ``cfg`` and the run's time step ``dt`` [s]
    (its time grid's: ``timegrid.TimeGrid``) (the integrator's ``a1``: the stiffness-proportional part of
    Rayleigh damping, -ssi_fem_rayleigh*); ``integrator``: the scheme's name (None: -ssi_fem_integrator; a
    coupled run's strategy names its own)."""
    name = cfg.fem_integrator if integrator is None else integrator
    if model is None:
        from .model import build_model
        model = build_model(cfg, comm)
    am, a1, note = damping(cfg)
    printf(f"[fem] {note}; integrator {name}, solver {cfg.fem_solver}")
    from .options import total_motion_damping_warning
    msg = total_motion_damping_warning(cfg, am)
    if msg:
        from ..petsc import warn
        warn(msg, comm)
    coords, near = near_null_args(cfg.fem_solver, model)
    from .modal_damping import build as modal_damping
    modal = modal_damping(cfg, model, comm)
    integ = make_integrator(name, model.K, model.m, dt, am, model.fixed,
                            cfg.fem_newmark_alpha, cfg.fem_newmark_delta, solver=cfg.fem_solver,
                            coords_vec=coords, near_null=near, a1=a1, modal=modal)
    return model, integ, am
