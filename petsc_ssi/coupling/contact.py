r"""Interface law per step: bonded, or unilateral contact with a cohesion limit.

The BEM step matrix A is factorised ONCE with every interface node closed
(traction unknown, u_b = u_f known). With the interface DOFs I, the step
matrix's displacement part H_s = c_1 H_1 + c_2 H_2 and

    y = A^{-1} (b - H_s E_I u_f)         (the bonded solution of the step)
    Z = A^{-1} H_s E_I                   (3 n_I solves, once, at set-up),

a set O of open DOFs (p_O = 0, u_O = u_f,O + delta_O unknown) changes only
the columns O of the system, and its solution is

    x = y - Z[:, O] delta_O,   Z_OO delta_O = y_O    (x_O = p_O = 0),

(p_O = t_O instead of 0 with -ssi_contact_open_traction cohesion: then
Z_OO delta_O = y_O - t_O), a capacitance (Schur complement) system of size |O|: a status change costs a
dense LU of Z_OO (cached per active set) and |O|-column products, never a
refactorisation of the BEM system. The algebra here works on replicated
interface arrays (3 n_I numbers); the caller applies x = y - Z[:, O] delta_O
to its own rows. Every rank solves the small system itself, but the status
decisions (which nodes open or close, when to stop) are taken on rank 0 and
broadcast (n_I booleans per iteration): ranks whose BLAS differ in the last
bit (heterogeneous nodes, run-time-dispatched kernels) could otherwise take
different active sets and deadlock or diverge.

Under a wave on a surface with an excavation the soil carries the scattered field and the free field has
a traction t_ff = sigma_ff n_b on the structure's faces below the ground (``offset``, per step): p_N and
the open nodes' target are taken on the total traction p + t_ff; on a plane surface t_ff = 0.

Kuhn-Tucker conditions (paper eq. 25), per node, n_b the soil's outward normal:
  gap     g = (u_b - u_f) . n_f = -delta . n_b        (g >= 0)
  traction p_N = p_b . n_b (tension positive)         (p_N <= p_C)
A closed node whose p_N exceeds p_C + tol opens; an open node whose gap is
below -tol (penetration) closes. An open node carries no traction (the method
notes' reading: p_C is a strength, lost when the node opens) or, with
open_traction 'cohesion', the normal tension p_C (eq. 25 read literally: the
complementarity (p_C - p_N) g = 0 makes p_N = p_C wherever g > 0). Step n starts from the status of step n-1;
B.2 closes open nodes whose predicted gap (u_b^{n-1} - u_f^n) . n_f is
negative; then solve / check / update until nothing changes. If a status set
repeats only the worst violation (relative to the traction and displacement
scales) is changed per iteration; if violations remain after ``max_iter``
iterations the step is accepted with a warning (cycling).

Static preload (-ssi_contact_preload, p_w >= 0 [N/m^2], uniform): the BEM works
on the dynamic increment from the static state, whose traction on the soil is
the compression -p_w n_b. The law acts on the total normal traction
p_N + (-p_w): a closed node opens when p_N > p_C + p_w, and an open node
carries total traction zero (or p_C n_b with open_traction 'cohesion'), i.e.
the dynamic traction (p_C + p_w) n_b or p_w n_b: the soil unloads by the
preload, and the structure (f = -M p) loses the same support. The gap is the
dynamic one (the static displacements of both sides are equal); p_w = 0 is
today's law bit for bit.
"""
import time

import numpy as np
import scipy.linalg as sla


class LUCache:
    """Dense LU factors cached per key (an active set), bounded by bytes (oldest out);
    counts the factorisations and their time (the cost of status changes)."""

    def __init__(self, n, cache_bytes=512e6):
        self.max_cache = max(1, int(cache_bytes // (8.0 * max(n, 1) ** 2)))
        self.cache = {}
        self.n_factor = 0
        self.t_factor = 0.0

    def get(self, key, matrix):
        """LU of ``matrix()`` (called only on a miss)."""
        lu = self.cache.get(key)
        if lu is None:
            t0 = time.perf_counter()
            lu = sla.lu_factor(matrix(), check_finite=False)
            self.t_factor += time.perf_counter() - t0
            self.n_factor += 1
            if len(self.cache) >= self.max_cache:
                self.cache.pop(next(iter(self.cache)))
            self.cache[key] = lu
        return lu


class Capacitance(LUCache):
    """Z_II (replicated, 3n_I x 3n_I) and LU factors of Z_OO cached per open set."""

    def __init__(self, Z_II, cache_bytes=512e6):
        self.Z = np.asarray(Z_II)
        super().__init__(len(self.Z), cache_bytes)

    def solve(self, O, yO):
        lu = self.get(O.tobytes(), lambda: self.Z[np.ix_(O, O)])
        return sla.lu_solve(lu, yO, check_finite=False)


class ContactLaw:
    """Replicated per-step active-set logic (see the module docstring).

    ``step(solve, uf_pred)``: ``solve(closed)`` returns (O, ub, uf, p) for a
    status (replicated interface arrays, 3 n_I); uf_pred is the structure's
    interface displacement used by the B.2 gap prediction (staggered step: the
    FEM predictor u_f^n), None to start from the previous status (implicit step:
    u_f^n depends on the interface force, there is no prediction)."""

    def __init__(self, n_b, zero, law="bonded", p_C=0.0, tol=1e-8, max_iter=25, open_traction="zero",
                 comm=None, preload=0.0):
        self.comm = comm if comm is not None and comm.Get_size() > 1 else None   # mpi4py
        self.n_b = np.asarray(n_b, float)            # (n_I, 3)
        self.open_traction = open_traction
        self.nI = len(self.n_b)
        self.zero = np.asarray(zero, bool).reshape(self.nI, 3)
        self.law = law
        self.p_C = float(p_C)
        self.preload = float(preload)                # p_w: the static compression [N/m^2], >= 0
        self.tol = float(tol)
        self.max_iter = int(max_iter)
        self.offset = None                           # the step's free-field traction t_ff (3 n_I) or None
        self.closed = np.ones(self.nI, bool)
        self.ub_prev = np.zeros(3 * self.nI)
        self.total_changes = 0
        self.cycled_steps = []
        self.t_algebra = 0.0

    def open_dofs(self, closed):
        m = np.repeat(~closed, 3) & ~self.zero.ravel()
        return np.nonzero(m)[0]

    def target(self, closed):
        """Dynamic traction prescribed at open DOFs (3n_I, zero elsewhere): the
        total traction 0, or with open_traction 'cohesion' the normal tension p_C
        n_b (eq. 25 read literally: an open node, g > 0, carries p_N = p_C),
        minus the preload's -p_w n_b: (p_w [+ p_C]) n_b."""
        t = np.zeros(3 * self.nI)
        p_open = self.p_C if (self.open_traction == "cohesion" and self.p_C > 0) else 0.0
        if p_open > 0 or self.preload > 0:
            tt = ((p_open + self.preload) * self.n_b) * (~closed)[:, None]
            t[:] = tt.ravel()
            t[self.zero.ravel()] = 0.0
        if self.offset is not None:                  # the soil carries t - t_ff: the total is the target
            t -= np.repeat(~closed, 3) * self.offset * ~self.zero.ravel()
        return t

    def total(self, p):
        """The total traction p + t_ff of the soil's (scattered) traction p: the free field's share on
        faces below the ground (``offset``; none on a plane surface)."""
        return p if self.offset is None else p + self.offset

    def _agree(self, obj):
        """Collective (with a comm): rank 0's decision on every rank."""
        return obj if self.comm is None else self.comm.bcast(obj, root=0)

    def _normal(self, v):
        return np.einsum("ij,ij->i", v.reshape(-1, 3), self.n_b)

    def step(self, solve, uf_pred):
        t0 = time.perf_counter()
        if self.law == "bonded":
            closed = self.closed
            O, ub, uf, p = solve(closed)
            its, changes, cycled = 1, 0, False
        else:
            closed = self.closed.copy()
            start = closed.copy()
            scale_u = max(np.abs(self.ub_prev).max(), 1e-300 if uf_pred is None else np.abs(uf_pred).max(), 1e-300)
            if uf_pred is not None:
                # B.2: predicted gap (u_b^{n-1} - u_f^n) . n_f of open nodes (n_f = -n_b)
                g_pred = -self._normal(self.ub_prev - uf_pred)
                closed |= (~closed) & (g_pred < -self.tol * scale_u)
                closed = self._agree(closed)
            seen = {closed.tobytes()}
            changes = int((closed != start).sum())
            cycled = False
            its = 0
            while True:
                its += 1
                O, ub, uf, p = solve(closed)
                pN = self._normal(self.total(p))
                gap = -self._normal(ub - uf)
                # violations relative to their own scales (tractions and displacements)
                sp = max(np.abs(p).max(), self.p_C, self.preload, 1e-300)
                su = max(scale_u, np.abs(uf).max(), np.abs(ub).max(), 1e-300)
                # total normal traction pN - p_w against p_C
                v_open = np.where(closed, (pN - self.p_C - self.preload) / sp - self.tol, -np.inf)  # > 0: open
                v_close = np.where(~closed, -gap / su - self.tol, -np.inf)              # > 0: must close
                viol = np.maximum(v_open, v_close)
                new = None
                if np.any(viol > 0) and its < self.max_iter:
                    new = closed.copy()
                    new[v_open > 0] = False
                    new[v_close > 0] = True
                    if new.tobytes() in seen:          # a repeated set: change the worst node only
                        new = closed.copy()
                        k = int(np.argmax(viol))
                        new[k] = not closed[k]
                new, cycled = self._agree((new, bool(np.any(viol > 0))))
                if new is None:
                    break                               # cycled: accepted with violations left
                changes += int((new != closed).sum())
                closed = new
                seen.add(closed.tobytes())
        pN = self._normal(self.total(p))
        gap = -self._normal(ub - uf)
        self.closed = closed
        self.ub_prev = ub
        self.total_changes += changes
        self.t_algebra += time.perf_counter() - t0
        return {"O": O, "p": p, "ub": ub, "uf": uf, "closed": closed.copy(), "gap": gap, "pN": pN,
                "iterations": its, "changes": changes, "cycled": cycled}


class StaggeredSolve:
    """The paper's staggered step (Table 2): u_f is fixed (the FEM predictor);
    closed DOFs get u_b = u_f, open ones p = 0 through the capacitance Z_OO."""

    def __init__(self, law, cap):
        self.law, self.cap = law, cap

    def __call__(self, y, uf):
        def solve(closed):
            O = self.law.open_dofs(closed)
            t = self.law.target(closed)
            delta = np.zeros_like(y)
            p = y.copy()
            if O.size:
                dO = self.cap.solve(O, y[O] - t[O])
                delta[O] = dO
                p -= self.cap.Z[:, O] @ dO
                p[O] = t[O]
            return O, uf + delta, uf, p
        return solve


class ImplicitSolve(LUCache):
    r"""Interface-implicit step: the structure's interface displacement responds
    to the interface force of the same step (trapezoidal Newmark, u_f = w + C f),
    solved together with the soil (p = q - Z u_b) on the interface:

        closed rows:  [(I - a C M3 Z) s]_C = [w - C M3 (a q + r)]_C     (u_b = u_f)
        open rows:    [Z s]_O = q_O - t_O                               (p_O = t_O)

    s = u_b, f = -M3 (a p + r) (a = 1, r = 0 for the direct traction; a = 1.5,
    r = -0.5 p^{n-1} extrapolated), C = [D^{-1}]_II, M3 = M (x) I_3. One dense
    LU per active set (cached), 3 n_I unknowns."""

    def __init__(self, law, Z, C, M3, a, cache_bytes=512e6):
        super().__init__(len(Z), cache_bytes)
        self.law, self.Z, self.C, self.M3, self.a = law, Z, C, M3, float(a)
        self.CM = C @ M3
        self.B = np.eye(len(Z)) - self.a * self.CM @ Z

    def _matrix(self, O):
        K = self.B.copy()
        K[O] = self.Z[O]
        return K

    def lu(self, closed, O=None):
        """The LU of the contact state ``closed`` (cached; ``O`` its open dofs, from the law when not
        given): the step's solve, or a factorisation made ahead (the bonded state, at set-up)."""
        O = self.law.open_dofs(closed) if O is None else O
        return self.get(closed.tobytes(), lambda: self._matrix(O))

    def __call__(self, q, w, r):
        g_closed = w - self.CM @ (self.a * q + r)

        def solve(closed):
            O = self.law.open_dofs(closed)
            t = self.law.target(closed)
            g = g_closed.copy()
            g[O] = q[O] - t[O]
            s = sla.lu_solve(self.lu(closed, O), g, check_finite=False)
            p = q - self.Z @ s
            p[O] = t[O]
            uf = w - self.CM @ (self.a * p + r)
            ub = s.copy()
            C = np.setdiff1d(np.arange(len(s)), O)
            ub[C] = uf[C]            # equal up to round-off; exact compatibility
            return O, ub, uf, p
        return solve
