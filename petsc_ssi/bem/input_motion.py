r"""Foundation input motion: a rigid MASSLESS surface footing under a seismic wave (kinematic
interaction; ``-ssi_disp_rigid massless``, ``petsc-ssi input-motion``).

The footing is the -ssi_disp_group region. Its total motion is an unknown rigid motion

    u(x, t_n) = R(x) q_n,   R(x) = [I | -skew(x - x_ref)],   q_n = (u_x, u_y, u_z, th_x, th_y, th_z)

(translations of the reference point x_ref [m], small rotations about it [rad]) and, the body having
no mass, the soil's traction on the region has zero resultant force and moment every step:

    W p_n = 0,    W: the region's resultant operator (``resultants.Resultants``, 6 x 3 n_t).

The BEM carries the scattered field (u_sc = u - u_ff on the region, t_ff = 0 on the flat surface;
on an excavation's walls and bottom, an embedded footing, the total traction is t_sc + t_ff and the
condition below carries the free field's resultant W_ff(n), ``free_field_resultant``).
A step of the march (``march.Marcher``) solves A x_n = b_n(history) - H_s kv_n, linear in the
known displacement kv_n of the region's DOFs. With kv_n = -u_ff(t_n) + R q_n,

    x_n = x_n^(0) + sum_k q_k X_k,      X_k = A^{-1} (-H_s R e_k)  (``Marcher.unit_response``)

where x_n^(0) is the step's solution with q = 0 (u_sc = -u_ff, the history of the massless footing
so far) and X_k the response of one step to a unit rigid mode k from rest (the same for every step:
the step matrix and its known-value terms do not change). The tractions follow, p_n = p_n^(0) +
sum_k q_k P_k, and the condition W p_n = 0 is the small system

    (W P) q_n = -W p_n^(0) - W_ff(n)       (6 x 6: the footing's instantaneous step stiffness),

solved every step; x_n and kv_n are then set to the q-solution before the march stores them, so
the history the next steps read is that of the massless footing (exact by linearity: no second
solve). Set-up costs one step solve per mode. With symmetry planes only the modes the planes allow
are unknown (the others vanish with the symmetric free field): e.g. y=anti (a wave along x
polarised along y) leaves u_y, th_x, th_z.

Output group ``input_motion`` (``arrays``; an embedded footing's also ``free_field_resultant``, the free
field's share of the condition, which the group ``resultants`` (the scattered traction's) does not hold):
per step the footing's translation [m], rotation [rad]
and their accelerations [m/s^2, rad/s^2] (second central differences of the step series), and the
free field at x_ref beside them: its displacement and its rotation, the rotation of the free
surface, 1/2 curl u_ff = (du_z/dy, -du_z/dx, (du_y/dx - du_x/dy)/2) at z = 0
(``seismic.input.SeismicInput.rotation``), with the same differences for their accelerations.
"""
import numpy as np

from ..petsc import SSIError, printf
from . import symmetry

NAMES = ("u_x", "u_y", "u_z", "theta_x", "theta_y", "theta_z")


def rigid_modes(x, xref):
    """(n, 3, 6): the nodal displacements of the six unit rigid modes about ``xref`` (translations
    e_x, e_y, e_z; rotations e_j x (x - xref))."""
    r = np.asarray(x, float) - np.asarray(xref, float)
    R = np.zeros((len(r), 3, 6))
    R[:, :, :3] = np.eye(3)
    for j in range(3):
        R[:, :, 3 + j] = np.cross(np.eye(3)[j], r)
    return R


def allowed_modes(x, xref, planes):
    """The rigid modes (indices into NAMES) that the symmetry ``planes`` allow: mode k about
    ``xref`` (on every plane) mirrored onto the region's nodes ``x`` equals S times itself."""
    R = rigid_modes(x, xref)
    keep = []
    for k in range(6):
        ok = True
        for ax, kind in planes:
            s = symmetry.sign_matrix(ax, kind)
            xr = np.array(x, float)
            xr[:, ax] *= -1.0
            Rr = rigid_modes(xr, xref)[:, :, k]
            ok &= bool(np.abs(Rr - s * R[:, :, k]).max() <= 1e-9 * max(np.abs(R[:, :, k]).max(), 1.0))
        if ok:
            keep.append(k)
    return keep


def region_centroid(mesh, regions, planes):
    """The centroid of the whole -ssi_disp_group region (its symmetry images included: on each plane
    the coordinate is 0) [m], from the area moments of its elements."""
    from .resultants import area_moments
    a, b = area_moments(mesh, regions.disp_elems, regions.disp_nodes)
    c = b.sum(0) / a.sum()
    c[np.abs(c) < 1e-12 * max(np.abs(mesh.nodes).max(), 1.0)] = 0.0        # (round-off of a centred region)
    for ax, _ in planes:
        c[ax] = 0.0
    c[2] = 0.0
    return c


def second_difference(q, dt):
    """Accelerations of a step series q (K, ...) sampled at t_n = n dt, n = 1..K, from rest (q_0 = 0):
    (q_{n+1} - 2 q_n + q_{n-1}) / dt^2, the last step's backward (q_K - 2 q_{K-1} + q_{K-2}) / dt^2."""
    q = np.asarray(q, float)
    z = np.concatenate([np.zeros((1,) + q.shape[1:]), q])          # q_0 .. q_K
    a = np.zeros_like(q)
    if len(q) >= 2:
        a[:-1] = (z[2:] - 2 * z[1:-1] + z[:-2]) / dt ** 2
        a[-1] = (z[-1] - 2 * z[-2] + z[-3]) / dt ** 2
    return a


class MasslessFooting:
    """Collective: the massless rigid footing of ``prob`` (a HalfSpace with -ssi_disp_rigid massless
    and a seismic input) driven through ``march`` (module docstring). ``correct`` is the march's step
    correction (``Marcher.step(correct)``); an observer of the recorder for checkpoints
    (``state``/``restore``) and its output group (``groups``: 'input_motion', ``arrays``)."""

    def __init__(self, comm, prob, march):
        from .resultants import Resultants
        self.comm, self.prob, self.march = comm, prob, march
        reg = prob.regions
        self.xref = prob.motion.xref
        x = prob.mesh.nodes[reg.disp_nodes]
        self.modes = allowed_modes(x, self.xref, prob.planes)
        R = rigid_modes(x, self.xref)
        self.res = Resultants(comm, prob, march.p_tmpl)
        self.U, self.X = [], []
        P = march.p_tmpl.duplicate()
        W = np.zeros((6, 6))
        for k in self.modes:
            U = march.u_tmpl.duplicate()
            U.set(0.0)
            if comm.getRank() == 0:
                U.setValues(march.dofs_pres, R[:, :, k].ravel())
            U.assemblyBegin(); U.assemblyEnd()
            X = march.u_tmpl.duplicate()
            march.unit_response(U, X)
            W[:, k] = self._resultant(march.traction_of(X, P))
            self.U.append(U)
            self.X.append(X)
        march.kv_u.set(0.0)
        self.P = P
        self.W = W                               # step stiffness: rows F [N], M [N m]; columns m, rad
        m = self.modes
        Wm = W[np.ix_(m, m)]
        d = 1.0 / np.sqrt(np.abs(np.diag(Wm)))
        self._Ws = Wm * d[:, None] * d[None, :]  # scaled: units drop out of the condition number
        self._d = d
        cond = np.linalg.cond(self._Ws)
        if not np.isfinite(cond) or cond > 1e12:
            raise SSIError(f"-ssi_disp_rigid massless: the footing's step stiffness is singular (condition "
                           f"{cond:.3g}); is the -ssi_disp_group region a surface patch of several elements?")
        self.q = []
        self._ff = self._free_field_traction()
        printf(f"[ssi] massless rigid footing: unknown rigid motion {', '.join(NAMES[k] for k in m)} about "
               f"x_ref = ({', '.join(f'{v:.6g}' for v in self.xref)}) m, zero resultant force and moment each step "
               f"(step stiffness condition {cond:.3g})")

    def _resultant(self, p):
        """Collective: the region's (F, M) of the traction Vec ``p`` on every rank (6,) [N, N m]."""
        self.res.R.mult(p, self.res.y)
        out = np.zeros(6)
        r0, r1 = self.res.R.getOwnershipRange()
        out[r0:r1] = self.res.y.getArray()
        return self.comm.tompi4py().allreduce(out)

    def _free_field_traction(self):
        """None on a flat surface (t_ff = 0 there); on an excavation's faces (an embedded footing) the
        free field's traction on the region's nodes (``sources.free_field.FreeFieldTraction``, the
        nodal normals of its tributary faces) with the region's area moments, for
        ``free_field_resultant``."""
        prob = self.prob
        if prob.seismic is None or prob.mesh.flat:
            return None
        if prob.planes:
            raise SSIError("-ssi_disp_rigid massless on a surface with an excavation takes no symmetry planes")
        from ..sources.free_field import FreeFieldTraction
        from .resultants import area_moments
        reg = prob.regions
        src = FreeFieldTraction(reg.disp_elems, name="free-field traction on the footing")
        idx = src.bind(prob.mesh, reg.disp_nodes)
        src.attach(prob.seismic)
        a, b = area_moments(prob.mesh, reg.disp_elems, reg.disp_nodes)
        return src, a[idx], b[idx] - a[idx, None] * self.xref

    def free_field_resultant(self, n):
        """(6,) the resultant force [N] and moment about x_ref [N m] of the free field's traction
        t_ff = sigma_ff n on the footing, its exact mean over step n (0 on a flat surface): the total
        traction on an embedded footing is t_sc + t_ff."""
        if self._ff is None:
            return np.zeros(6)
        src, a, r = self._ff
        t = -src.step_mean(n, self.prob.dt)                  # (the source's step mean is -t_ff)
        return np.r_[a @ t, np.cross(r, t).sum(0)]

    def correct(self, n, x):
        """Collective: the step's q from the zero-resultant condition; x and the march's known
        displacement kv_u set to the q-solution (``Marcher.step``)."""
        f0 = self._resultant(self.march.traction_of(x, self.P)) + self.free_field_resultant(n)
        m = self.modes
        qm = -self._d * np.linalg.solve(self._Ws, self._d * f0[m])
        x.maxpy(list(qm), self.X)
        self.march.kv_u.maxpy(list(qm), self.U)
        q = np.zeros(6)
        q[m] = qm
        self.q.append(q)

    # ------------------------------------------------------------ recorder protocol (checkpoints)
    def observe(self, n, t, step):
        """(q of step n is kept by ``correct``)"""

    def state(self, n_times):
        return {"input_motion_q": np.array(self.q).reshape(-1, 6)}

    def restore(self, s, n=None):
        self.q = [row.copy() for row in np.asarray(s["input_motion_q"]).reshape(-1, 6)]

    # ------------------------------------------------------------ output
    def groups(self, steps, times):
        """The recorder's protocol (``io.recorder``): {'input_motion': ``arrays(times)``}."""
        return {"input_motion": self.arrays(times)}

    def free_field(self, times):
        """(u (K, 3) [m], rotation (K, 3) [rad]): the free field at x_ref."""
        s = self.prob.seismic
        t = np.asarray(times, float)
        pt = self.xref[None, :]
        return s.u(pt, t)[:, 0, :], s.rotation(pt, t)[:, 0, :]

    def arrays(self, times):
        """{name: (array, unit)}: the output group 'input_motion' (module docstring)."""
        dt = self.prob.dt
        q = np.array(self.q).reshape(-1, 6)
        uff, rff = self.free_field(times)
        acc = second_difference(q, dt)
        aff = second_difference(np.c_[uff, rff], dt)
        diff = "(second central difference of the step series; backward at the last step)"
        extra = {}
        if self._ff is not None:          # an embedded footing: the output's 'resultants' are the scattered part
            extra["free_field_resultant"] = (
                np.array([self.free_field_resultant(n) for n in range(1, len(q) + 1)]).reshape(-1, 6),
                "F_x, F_y, F_z [N], M_x, M_y, M_z [N m] about x_ref: the free field's traction sigma_ff n on the "
                "footing, each step's mean; plus the group 'resultants' (the scattered traction's) it is zero")
        return extra | {
            "t": (np.asarray(times, float), "s"),
            "translation": (q[:, :3], "m (displacement of x_ref: x, y, z)"),
            "rotation": (q[:, 3:], "rad (small rotation about the axes through x_ref: x, y, z)"),
            "acceleration": (acc[:, :3], "m/s^2 " + diff),
            "angular_acceleration": (acc[:, 3:], "rad/s^2 " + diff),
            "free_field_translation": (uff, "m (free-field displacement at x_ref)"),
            "free_field_rotation": (rff, "rad (free-surface rotation 1/2 curl u_ff at x_ref)"),
            "free_field_acceleration": (aff[:, :3], "m/s^2 " + diff),
            "free_field_angular_acceleration": (aff[:, 3:], "rad/s^2 " + diff),
            "x_ref": (self.xref, "m"),
            "modes": (np.array(self.modes, np.int64), "indices of the unknown modes in (u_x, u_y, u_z, theta_x, "
                                                       "theta_y, theta_z); the others vanish by symmetry"),
            "step_stiffness": (self.W, "rows F_x, F_y, F_z [N], M_x, M_y, M_z [N m]; columns per unit u [m] and "
                                       "theta [rad]: the resultant of one step's response from rest"),
        }


def check_soil_around(mesh, elems, group, tol, who="petsc-ssi impedance"):
    """SSIError unless the footing ``elems`` is a part of the meshed surface with soil all around it:
    not the whole surface, and touching the surface's outer edge nowhere (edges on a plane x = 0 or
    y = 0 of a half model excepted: the soil continues in the mirror image). An impedance of a
    footing without soil around it is not the footing's, and its comparison with the published
    curves meaningless."""
    if len(elems) == mesh.n_cells:
        raise SSIError(f"-ssi_disp_group {group}: the footing is the whole meshed surface; {who} "
                       "needs the footing as a part of the surface with soil around it (mesh a larger surface or "
                       "name a smaller group)")
    corners = mesh.cells[:, :4]
    edges = np.sort(np.stack([corners, np.roll(corners, -1, axis=1)], -1).reshape(-1, 2), axis=1)
    uniq, count = np.unique(edges, axis=0, return_counts=True)
    outer = np.unique(uniq[count == 1])
    X = mesh.nodes
    for ax in (0, 1):                          # a half model's edge on its plane is not an edge of the soil
        if X[:, ax].min() > -tol and np.abs(X[:, ax]).min() < tol:
            outer = outer[np.abs(X[outer, ax]) > tol]
    foot = np.unique(mesh.cells[elems])
    touch = np.intersect1d(foot, outer)
    if touch.size:
        p = X[touch[0]]
        raise SSIError(f"-ssi_disp_group {group}: the footing reaches the edge of the meshed surface (at "
                       f"x = {p[0]:.4g}, y = {p[1]:.4g} m); {who} needs soil around the footing "
                       "(mesh a larger surface)")
