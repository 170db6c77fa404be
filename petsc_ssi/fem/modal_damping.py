r"""Modal damping of the structure (issue 43): a damping ratio per natural mode.

    C_modal = sum_i c_i (M phi_i)(M phi_i)^T,   c_i = 2 zeta_i omega_i,   phi_i^T M phi_i = 1

over the first n flexible modes of the structure on its supports (``modes.compute_modes``: the fixed
dofs of a fixed base; a structure on the soil has none and its rigid-body modes, omega = 0, are left
out). By M-orthogonality phi_j^T C_modal phi_i = 2 zeta_i omega_i delta_ij: mode i keeps exactly the
ratio zeta_i (added to Rayleigh's alpha_m/(2 omega) + a1 omega/2 when both are given), the modes above
n get none from it, and a rigid-body motion (M-orthogonal to every flexible mode) none at all.

C_modal is a full matrix of rank n; it is never formed. Each integrator's step matrix is
D = D0 + s U S U^T with D0 its matrix without the modal part (factorised once, as before), U = [M phi_i]
(n Vecs), S = diag(c_i) and s the scheme's factor of C in D (delta/(alpha dt); 2/dt for the trapezoidal
rule). A solve with D is the solve with D0 and the Sherman-Morrison-Woodbury correction

    D^{-1} b = x0 - Z A^{-1} U^T x0,   x0 = D0^{-1} b,   Z = D0^{-1} U,   A = (s S)^{-1} + U^T Z

(Z: n solves with D0 at set-up; A: n x n, replicated). Cost: n extra solves and 2n Vecs at set-up,
then per solve n dot products (one reduction) and n updates, and per step one product with C_modal
(n dots, n updates) in the right-hand side. The modes with zeta_i = 0 carry nothing and are dropped.

The damping forces C_modal v act between the structure and a fixed frame (like alpha_m M's): they are
not reactions at the supports, so the base shear from the supports' reactions does not hold them.
"""
import math

import numpy as np

from ..petsc import SSIError, printf

DEFAULT_MODES = 10                  # flexible modes damped when one ratio is given without a count


def parse_ratios(text):
    """'z' or 'z1,z2,...' -> list of floats; SSIError on anything else."""
    try:
        vals = [float(x) for x in str(text).replace(";", ",").split(",") if x.strip()]
    except ValueError:
        vals = []
    if not vals:
        raise SSIError(f"-ssi_fem_modal_damping '{text}': expected a damping ratio 'z' or one per mode 'z1,z2,...'")
    return vals


def check_options(cfg):
    """One line when -ssi_fem_modal_damping / -ssi_fem_modal_modes are given wrongly (None otherwise)."""
    text = str(cfg.get("fem_modal_damping", "") or "").strip()
    n = int(cfg.get("fem_modal_modes", 0) or 0)
    if not text:
        return ("-ssi_fem_modal_modes is set without -ssi_fem_modal_damping (the ratios it would apply)"
                if cfg.user_set("fem_modal_modes") else None)
    try:
        z = parse_ratios(text)
    except SSIError as exc:
        return str(exc)
    bad = [v for v in z if not (math.isfinite(v) and 0.0 <= v < 1.0)]
    if bad:
        return (f"-ssi_fem_modal_damping {text}: a damping ratio must lie in [0, 1) (got {bad[0]:g}; 0.05 is 5 % "
                "of critical)")
    if len(z) > 1 and n and n != len(z):
        return (f"-ssi_fem_modal_damping gives {len(z)} ratios and -ssi_fem_modal_modes {n} modes: give one ratio "
                "for n modes, or one ratio per mode without -ssi_fem_modal_modes")
    if n < 0:
        return f"-ssi_fem_modal_modes {n}: must be >= 1"
    a, d = cfg.fem_newmark_alpha, cfg.fem_newmark_delta
    if cfg.get("fem_integrator", "green") == "green" and (abs(a - 0.25) > 1e-12 or abs(d - 0.5) > 1e-12):
        return (f"modal damping with -ssi_fem_integrator green needs the trapezoidal rule (Newmark alpha 1/4, "
                f"delta 1/2; got {a:g}, {d:g}); -ssi_fem_integrator newmark takes any alpha, delta")
    return None


def ratios_of(cfg):
    """The ratios zeta_i of the damped modes (list; empty without -ssi_fem_modal_damping)."""
    text = str(cfg.get("fem_modal_damping", "") or "").strip()
    if not text:
        return []
    z = parse_ratios(text)
    if len(z) == 1:
        return z * (int(cfg.get("fem_modal_modes", 0) or 0) or DEFAULT_MODES)
    return z


class ModalDamping:
    """Collective: C_modal of the ratios ``zetas`` (one per flexible mode, lowest first) of the structure
    (K, m: its stiffness Mat and lumped-mass Vec; ``fixed``: its fixed dofs). Module docstring."""

    def __init__(self, K, m, fixed, zetas, comm, prefix="ssi_fem_modal_"):
        from .modes import compute_modes, default_target
        self.comm = comm
        zetas = [float(z) for z in zetas]
        n = len(zetas)
        ndof = K.getSize()[0] - len(fixed)
        want = min(n + 6, ndof)                   # room for up to six rigid-body modes of a free structure
        if n > ndof:
            raise SSIError(f"-ssi_fem_modal_damping: {n} modes asked, the structure has {ndof} free dofs")

        class _Model:                             # what default_target reads
            pass
        mdl = _Model()
        mdl.K, mdl.m, mdl.fixed = K, m, fixed
        freqs, shapes = compute_modes(K, m, fixed, want, default_target(mdl, None), prefix=prefix)
        lam = (2 * math.pi * freqs) ** 2
        rigid = lam <= 1e-8 * max(float(lam.max()), 1e-300)
        flex = [i for i in range(len(freqs)) if not rigid[i]]
        if len(flex) < n:
            for s in shapes:
                s.destroy()
            raise SSIError(f"-ssi_fem_modal_damping: {n} flexible modes asked, {len(flex)} found below "
                           f"{freqs.max():.4g} Hz ({int(rigid.sum())} rigid-body modes left out)")
        self.n_rigid = int(rigid[:flex[n - 1]].sum())
        self.freqs = freqs[flex[:n]]
        self.zetas = np.array(zetas)
        keep = [k for k in range(n) if zetas[k] > 0]
        cols, c = [], []
        for k in keep:
            phi = shapes[flex[k]]
            u = phi.duplicate()
            u.pointwiseMult(phi, m)                 # M phi (lumped)
            mn = phi.dot(u)                         # phi^T M phi
            cols.append(u.getArray(readonly=True) / math.sqrt(mn))    # M phi_i, phi_i M-normalised
            c.append(2.0 * zetas[k] * 2 * math.pi * self.freqs[k])
            u.destroy()
        for s in shapes:
            s.destroy()
        nloc = m.getLocalSize()
        # the local rows of U = [M phi_i] and, after bind(), of Z = D0^{-1} U: numpy (n_local, n_damped)
        self.U = np.column_stack(cols) if cols else np.zeros((nloc, 0))
        self.c = np.array(c)
        self.Z = None
        self.Ainv = None
        self.work = m.duplicate() if cols else None

    @property
    def active(self):
        return self.U.shape[1] > 0

    def describe(self):
        """One line for the log: ratios, frequencies, cost."""
        f = self.freqs
        z = np.unique(self.zetas)
        k = self.U.shape[1]
        zt = f"zeta {z[0]:g}" if z.size == 1 else f"zeta {', '.join(f'{v:g}' for v in self.zetas[:6])}" + \
            (", ..." if len(self.zetas) > 6 else "")
        return (f"modal damping C_modal = sum 2 zeta_i omega_i (M phi_i)(M phi_i)^T, {zt} in the first {len(f)} flexible "
                f"modes ({f[0]:.4g} to {f[-1]:.4g} Hz; higher modes get none from it"
                + (f", {self.n_rigid} rigid-body modes left out" if self.n_rigid else "")
                + f"): {k} extra solves at set-up, {k} dot products and updates per solve and per step")

    def attrs(self):
        """Output attributes (frequencies in Hz, ratios)."""
        return {"modal_damping_frequencies_hz": np.asarray(self.freqs, float),
                "modal_damping_ratios": np.asarray(self.zetas, float)}

    # ------------------------------------------------------------ products
    def _coeffs(self, x, V=None):
        """V^T x (V: U by default; every rank: one reduction)."""
        from mpi4py import MPI
        V = self.U if V is None else V
        loc = V.T @ x.getArray(readonly=True)
        return self.comm.tompi4py().allreduce(loc, op=MPI.SUM) if self.comm.getSize() > 1 else loc

    def mult_add(self, x, y, scale=1.0):
        """Collective: y += scale C_modal x."""
        if self.active:
            a = scale * self.c * self._coeffs(x)
            y.getArray()[:] += self.U @ a
        return y

    # ------------------------------------------------------------ the solve with D = D0 + s U S U^T
    def bind(self, solve0, s, template):
        """Collective: Z = D0^{-1} U by ``solve0(b, x)`` (the solve with D0) and A^{-1}; ``s``: the
        scheme's factor of C in its step matrix."""
        if not self.active:
            return
        b, z = template.duplicate(), template.duplicate()
        self.Z = np.empty_like(self.U)
        for j in range(self.U.shape[1]):
            b.getArray()[:] = self.U[:, j]
            solve0(b, z)
            self.Z[:, j] = z.getArray(readonly=True)
        b.destroy()
        z.destroy()
        from mpi4py import MPI
        A = self.U.T @ self.Z
        if self.comm.getSize() > 1:
            A = self.comm.tompi4py().allreduce(A, op=MPI.SUM)
        A = 0.5 * (A + A.T) + np.diag(1.0 / (s * self.c))
        self.Ainv = np.linalg.inv(A)

    def correct(self, x):
        """Collective: x0 = D0^{-1} b -> D^{-1} b (in place)."""
        if self.active:
            y = self.Ainv @ self._coeffs(x)
            x.getArray()[:] -= self.Z @ y
        return x

    def destroy(self):
        if self.work is not None:
            self.work.destroy()
        self.U, self.Z, self.work = np.zeros((0, 0)), None, None


def build(cfg, model, comm):
    """Collective: the ModalDamping of the options (None without -ssi_fem_modal_damping), logged."""
    z = ratios_of(cfg)
    if not z:
        return None
    md = ModalDamping(model.K, model.m, model.fixed, z, comm)
    printf(f"[fem] {md.describe()}")
    return md
