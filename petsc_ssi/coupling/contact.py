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
today's law bit for bit. With -ssi_contact_preload earth:K0 p_w is per node (the lateral earth pressure at rest
on an excavation's walls, the weight on its bottom: ``step.earth_preload``).

What an open node keeps of the bond (-ssi_contact_separation): 'free' nothing (every component of its traction
prescribed). On an excavation's walls that law can have no consistent status at a node: closed, it is in
(small) normal tension; freed, the release of its (large) shear pushes its soil into the pit (g < 0). 'auto'
then keeps the node's tangential bond and releases its normal traction only ("stuck": in its frame (t1, t2, n),
rows t.(u_b - u_f) = 0 and n.p = n.target; g >= 0 is still checked) for the rest of the step; a stuck node that
penetrates closes, and a closed node that had been stuck in the step reopens stuck. 'normal' makes every open
node stuck. Nodes start each step free (``stick`` is per iterate, not carried between steps).
"""
import time

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp


def normal_frames(n):
    """Per node an orthonormal frame (n_I, 3, 3), rows t1, t2, n: t1 the first axis least aligned with n
    projected off it, t2 = n x t1."""
    n = np.asarray(n, float)
    e = np.eye(3)[np.argmin(np.abs(n), axis=1)]
    t1 = e - np.einsum("ij,ij->i", e, n)[:, None] * n
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    return np.stack([t1, np.cross(n, t1), n], axis=1)


def stuck_rows(frames, S):
    """The rows 3k..3k+2 of the stuck nodes S (flat index array) and their frames (|S|, 3, 3)."""
    return (3 * S[:, None] + np.arange(3)).ravel(), frames[S]


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
                 comm=None, preload=0.0, separation="free"):
        self.comm = comm if comm is not None and comm.Get_size() > 1 else None   # mpi4py
        self.n_b = np.asarray(n_b, float)            # (n_I, 3)
        self.open_traction = open_traction
        self.nI = len(self.n_b)
        self.zero = np.asarray(zero, bool).reshape(self.nI, 3)
        self.law = law
        self.p_C = float(p_C)
        # p_w: the static compression [N/m^2], >= 0: uniform, or per node (n_I,) (-ssi_contact_preload earth:K0)
        self.preload = float(preload) if np.ndim(preload) == 0 else np.asarray(preload, float)
        self.tol = float(tol)
        self.max_iter = int(max_iter)
        self.offset = None                           # the step's free-field traction t_ff (3 n_I) or None
        self.closed = np.ones(self.nI, bool)
        self.separation = separation                 # free | normal | auto (module docstring)
        self.stick = np.zeros(self.nI, bool)         # open nodes whose tangential bond is kept (this iterate)
        self.frames = normal_frames(self.n_b)        # (n_I, 3, 3): rows t1, t2, n_b
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
        pw = self.preload if np.ndim(self.preload) == 0 else self.preload[:, None]
        if p_open > 0 or np.any(self.preload > 0):
            tt = ((p_open + pw) * self.n_b) * (~closed)[:, None]
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

    def key(self, closed, stick=None):
        """The cache key of a contact state: the closed set, and the stuck open nodes when there are any."""
        stick = self.stick if stick is None else stick
        return closed.tobytes() + (stick.tobytes() if stick.any() else b"")

    def open_free_dofs(self, closed):
        """The open dofs free in every direction (not stuck; not fixed by a symmetry plane) and the stuck
        open nodes (their normal released, their tangential bond kept)."""
        stuck = self.stick & ~closed
        m = np.repeat(~closed & ~stuck, 3) & ~self.zero.ravel()
        return np.nonzero(m)[0], np.nonzero(stuck)[0]

    def _violations(self, closed, pN, gap, p, ub, uf, scale_u):
        """Each node's violation relative to its own scale (> 0: its status must change): a closed node's
        total normal traction p_N - p_w beyond p_C, an open node's penetration."""
        sp = max(np.abs(p).max(), self.p_C, np.max(self.preload), 1e-300)
        su = max(scale_u, np.abs(uf).max(), np.abs(ub).max(), 1e-300)
        v_open = np.where(closed, (pN - self.p_C - self.preload) / sp - self.tol, -np.inf)   # > 0: open
        v_close = np.where(~closed, -gap / su - self.tol, -np.inf)                          # > 0: must close
        return v_open, v_close

    def _move(self, closed, stick, barred, flip):
        """The statuses after changing the nodes ``flip`` (separation free: open <-> closed; auto: a
        closed node opens free unless it penetrated free in this step (``barred``: then it opens stuck),
        a free open node that penetrates is stuck (and barred), a stuck one closes; normal: every open
        node stuck)."""
        new, st = closed.copy(), stick.copy()
        if self.separation == "auto":
            to_stick = flip & ~closed & ~stick
            barred |= to_stick
            st[to_stick] = True
            shut = flip & ~closed & stick
            new[shut], st[shut] = True, False
            opening = flip & closed
            new[opening], st[opening] = False, barred[opening]
        else:
            new[flip] = ~closed[flip]
            st = ~new if self.separation == "normal" else st
        return new, st

    def _iterate(self, solve, closed, start, scale_u):
        """The active-set loop of a unilateral step from the status ``closed``: solve, check, update until
        nothing changes (a repeated status set: only the worst violation changes) or ``max_iter``."""
        self.stick = ~closed if self.separation == "normal" else np.zeros(self.nI, bool)
        barred = np.zeros(self.nI, bool)
        seen = {self.key(closed)}
        changes = int((closed != start).sum())
        its = 0
        while True:
            its += 1
            sol = solve(closed)
            O, ub, uf, p = sol
            v_open, v_close = self._violations(closed, self._normal(self.total(p)), -self._normal(ub - uf),
                                               p, ub, uf, scale_u)
            viol = np.maximum(v_open, v_close)
            new = None
            if np.any(viol > 0) and its < self.max_iter:
                new, stick = self._move(closed, self.stick, barred, viol > 0)
                if self.key(new, stick) in seen:    # a repeated set: change the worst node only
                    k = int(np.argmax(viol))
                    new, stick = self._move(closed, self.stick, barred, np.arange(self.nI) == k)
                new = (new, stick)
            new, cycled = self._agree((new, bool(np.any(viol > 0))))
            if new is None:
                break                               # settled, or cycled: accepted with violations left
            changes += int((new[0] != closed).sum() + (new[1] != self.stick).sum())
            closed, self.stick = new
            seen.add(self.key(closed))
        return closed, its, changes, cycled, sol

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
            closed, its, changes, cycled, (O, ub, uf, p) = self._iterate(solve, closed, start, scale_u)
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
            law = self.law
            if law.stick.any():
                return self._stuck(closed, y, uf)
            O = law.open_dofs(closed)
            t = law.target(closed)
            delta = np.zeros_like(y)
            p = y.copy()
            if O.size:
                dO = self.cap.solve(O, y[O] - t[O])
                delta[O] = dO
                p -= self.cap.Z[:, O] @ dO
                p[O] = t[O]
            return O, uf + delta, uf, p
        return solve

    def _stuck(self, closed, y, uf):
        """With stuck open nodes (their tangential bond kept): the jump delta = E c in the basis E of the
        free open dofs' unit vectors and the stuck nodes' normals, E^T Z E c = E^T (y - t), p = y - Z E c."""
        law = self.law
        O, S = law.open_free_dofs(closed)
        t = law.target(closed)
        rows, R = stuck_rows(law.frames, S)
        nS = law.n_b[S]
        Z = self.cap.Z
        # E's columns are unit vectors (the free open dofs) and the stuck nodes' normals: Z E and E^T v by
        # gathering, not by products with the mostly zero E

        def ET(V):                                   # E^T V for V (3 n_I, ...)
            Vs = V[rows].reshape((len(S), 3) + V.shape[1:])
            return np.concatenate([V[O], np.einsum("sb,sb...->s...", nS, Vs)])
        ZE = np.concatenate([Z[:, O], np.einsum("isb,sb->is", Z[:, rows].reshape(len(y), len(S), 3), nS)], axis=1)
        lu = self.cap.get(law.key(closed), lambda: ET(ZE))
        c = sla.lu_solve(lu, ET(y - t), check_finite=False)
        delta = np.zeros_like(y)
        delta[O] = c[:len(O)]
        delta[rows] = (nS * c[len(O):, None]).ravel()
        p = y - ZE @ c
        p[O] = t[O]
        if S.size:                                   # the stuck nodes' normal traction exactly the target
            pk, tk = p[rows].reshape(-1, 3), t[rows].reshape(-1, 3)
            pk += law.n_b[S] * np.einsum("ij,ij->i", tk - pk, law.n_b[S])[:, None]
            p[rows] = pk.ravel()
        return np.union1d(O, rows), uf + delta, uf, p


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
        # C M3 with M3 = M (x) I_3 sparse (a few entries a row): the dense product's 2 (3 n_I)^3 flops were
        # about half of this set-up on the uniform 72 m building (a scratch cProfile)
        self.CM = np.ascontiguousarray((sp.csr_matrix(M3).T @ np.asarray(C).T).T)
        self.B = np.eye(len(Z)) - self.a * self.CM @ Z

    def _matrix(self, O, S=None):
        K = self.B.copy()
        K[O] = self.Z[O]
        if S is not None and S.size:                 # stuck nodes: tangential rows t.(u_b - u_f) = 0,
            rows, R = stuck_rows(self.law.frames, S)     # the normal row n.p = n.t
            Kr = np.einsum("sab,sbj->saj", R, K[rows].reshape(len(S), 3, -1))
            Kr[:, 2] = np.einsum("sb,sbj->sj", self.law.n_b[S], self.Z[rows].reshape(len(S), 3, -1))
            K[rows] = Kr.reshape(len(rows), -1)
        return K

    def lu(self, closed, O=None):
        """The LU of the contact state ``closed`` (cached; ``O`` its open dofs, from the law when not
        given): the step's solve, or a factorisation made ahead (the bonded state, at set-up)."""
        if self.law.stick.any():
            O, S = self.law.open_free_dofs(closed)
            return self.get(self.law.key(closed), lambda: self._matrix(O, S))
        O = self.law.open_dofs(closed) if O is None else O
        return self.get(closed.tobytes(), lambda: self._matrix(O))

    def __call__(self, q, w, r):
        g_closed = w - self.CM @ (self.a * q + r)

        def solve(closed):
            if self.law.stick.any():
                return self._stuck(closed, q, w, r, g_closed)
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

    def _stuck(self, closed, q, w, r, g_closed):
        """The solve with stuck open nodes: their rows rotated into their frame (``_matrix``); afterwards
        their normal traction is the target and their tangential displacement the structure's, exactly."""
        law = self.law
        O, S = law.open_free_dofs(closed)
        t = law.target(closed)
        rows, R = stuck_rows(law.frames, S)
        g = g_closed.copy()
        g[O] = q[O] - t[O]
        gr = np.einsum("sab,sb->sa", R, g[rows].reshape(-1, 3))
        gr[:, 2] = np.einsum("sb,sb->s", law.n_b[S], (q - t)[rows].reshape(-1, 3))
        g[rows] = gr.ravel()
        s = sla.lu_solve(self.lu(closed), g, check_finite=False)
        p = q - self.Z @ s
        p[O] = t[O]
        nS = law.n_b[S]
        pk, tk = p[rows].reshape(-1, 3), t[rows].reshape(-1, 3)
        pk += nS * np.einsum("ij,ij->i", tk - pk, nS)[:, None]
        p[rows] = pk.ravel()
        uf = w - self.CM @ (self.a * p + r)
        ub = uf.copy()
        ub[O] = s[O]
        d = (s - uf)[rows].reshape(-1, 3)             # the stuck nodes' jump: its normal part only
        ub[rows] = (uf[rows].reshape(-1, 3) + nS * np.einsum("ij,ij->i", d, nS)[:, None]).ravel()
        return np.union1d(O, rows), ub, uf, p
