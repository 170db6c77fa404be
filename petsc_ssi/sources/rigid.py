"""A soil region's rigid-body motion as a source: prescribed, or the unknown motion of a massless footing.

Both load the soil through its displacement on the region's elements (the BEM's prescribed-displacement
region, ``bem.lagset.Regions``), not through a traction. The soil takes at most one of them (``sources``
argument of ``bem.halfspace.HalfSpace``).

``PrescribedRigidMotion``: on the region the rigid motion

    u(x, t) = h(t) [u0 + theta0 x (x - x_ref)]

(u0 a translation [m], theta0 small rotations [rad] about the axes through x_ref [m], h a scalar
history, ``petsc_ssi.histories``), sampled at t_n. The run records the resultants of the region's
traction (``bem.resultants.Resultants``) about x_ref.

``MasslessRigidFooting``: the region is a rigid body with no mass under a seismic input (kinematic
interaction): its rigid motion q_n (translations of x_ref, rotations about it) is the unknown of
every step, fixed by a zero resultant force and moment of the soil's traction on it. The known
displacement the march starts each step from is zero on the region (the soil then carries
u_sc = -u_ff there); the footing's correction (``bem.input_motion.MasslessFooting``, built by
``correction`` once the march exists) solves for q_n. x_ref defaults to the region's centroid
(symmetry images included), the seismic input's control point.

The prescribed-motion protocol (what the soil calls):

    elements                      the soil elements of the region (int array)
    massless                      whether the motion is the massless footing's unknown
    bind(mesh, regions, planes, h)  once the soil's regions exist (``regions.disp_nodes`` the region's
                                  nodes, in the traction columns' order), its symmetry planes and
                                  element size h [m]: evaluates the motion at the nodes, checks it
                                  (SSIError)
    factor(t)                     h(t)
    values(t)                     the displacements (3 n_disp,) [m] at the region's nodes at time t
    control_point(mesh, regions, planes)  the seismic input's default control point [m]
    correction(comm, prob, march)  the march's step correction (``Marcher.step(correct)``) and an
                                  observer of the recorder, or None
    describe()                    one line for the run's log

``rigid_motion(cfg, mesh)`` makes the source the options describe (-ssi_disp_group, -ssi_disp_value,
-ssi_disp_rotation, -ssi_disp_ref, -ssi_disp_history, -ssi_disp_rigid).
"""
import numpy as np

from ..petsc import SSIError, warn
from ..histories import History
from ..bem import symmetry
from ..bem.resultants import parse_vector


class PrescribedRigidMotion:
    """h(t) [u0 + theta0 x (x - x_ref)] on ``elements`` (module docstring); ``history`` a callable h(t)."""

    massless = False

    def __init__(self, elements, u0, theta, history, xref=(0.0, 0.0, 0.0), name="prescribed rigid motion"):
        self.elements = np.asarray(elements, np.int64)
        self.u0, self.theta = np.asarray(u0, float), np.asarray(theta, float)
        self.xref = None if xref is None else np.asarray(xref, float)
        self.history, self.name = history, name
        self.x = self.base = None

    def bind(self, mesh, regions, planes, h):
        """The motion at the region's nodes (``regions.disp_nodes``); SSIError if the symmetry planes
        contradict it."""
        self.x = mesh.nodes[regions.disp_nodes]
        self.base = (self.u0 + np.cross(self.theta, self.x - self.xref)).ravel()     # (3 n_disp,)
        self._check_symmetry(planes)

    def _check_symmetry(self, planes):
        """u(R x) = S u(x) about every plane (S its sign pattern): the motion must be of the
        declared kind, and x_ref must lie on the plane where a rotation makes it matter."""
        for ax, kind in planes:
            s = symmetry.sign_matrix(ax, kind)
            xr = self.x.copy()
            xr[:, ax] *= -1.0
            u = self.u0 + np.cross(self.theta, self.x - self.xref)
            ur = self.u0 + np.cross(self.theta, xr - self.xref)
            scale = max(np.abs(u).max(), 1e-300)
            if np.abs(ur - s * u).max() > 1e-9 * scale:
                name = f"{'xy'[ax]}={'sym' if kind > 0 else 'anti'}"
                raise SSIError(f"-ssi_symmetry {name}: the prescribed motion (-ssi_disp_value "
                               f"{','.join(f'{v:g}' for v in self.u0)}, -ssi_disp_rotation "
                               f"{','.join(f'{v:g}' for v in self.theta)} about -ssi_disp_ref "
                               f"{','.join(f'{v:g}' for v in self.xref)}) is not "
                               f"{'symmetric' if kind > 0 else 'antisymmetric'} about this plane")

    def factor(self, t):
        """h(t)."""
        return float(self.history(t))

    def values(self, t):
        """The displacements (3 n_disp,) [m] of the region's nodes at time t."""
        return self.base * self.factor(t)

    def control_point(self, mesh, regions, planes):
        """The mean of the region's nodes [m]."""
        return mesh.nodes[regions.disp_nodes].mean(0)

    def correction(self, comm, prob, march):
        """None: the motion is known."""
        return None

    def describe(self):
        return (f"{self.name}: {self.elements.size} elements, u0 ({', '.join(f'{v:.6g}' for v in self.u0)}) m, "
                f"theta0 ({', '.join(f'{v:.6g}' for v in self.theta)}) rad about x_ref "
                f"({', '.join(f'{v:.6g}' for v in self.xref)}) m, history {getattr(self.history, 'kind', '?')}")


class MasslessRigidFooting(PrescribedRigidMotion):
    """The rigid massless footing on ``elements`` (module docstring); ``xref``: its reference point [m],
    None for the region's centroid; ``history``: the factor of its (zero) known motion, recorded
    beside the resultants; ``group``: the region's name in messages."""

    massless = True

    def __init__(self, elements, history, xref=None, group="", name="massless rigid footing", ref_text=None):
        super().__init__(elements, np.zeros(3), np.zeros(3), history, xref, name)
        self.group = group
        given = () if self.xref is None else self.xref
        self.ref_text = ref_text if ref_text is not None else ",".join(f"{v:g}" for v in given)

    def bind(self, mesh, regions, planes, h):
        """Refuses a footing without soil around it and a reference point off a symmetry plane; the
        default reference point is the region's centroid."""
        from ..bem.input_motion import check_soil_around, region_centroid
        check_soil_around(mesh, self.elements, self.group, 1e-6 * h, who="a massless footing (input-motion)")
        if self.xref is None:
            self.xref = region_centroid(mesh, regions, planes)
        for ax, _ in planes:
            if abs(self.xref[ax]) > 1e-9 * max(h, 1.0):
                sym = ",".join(f"{'xy'[a]}={'sym' if k > 0 else 'anti'}" for a, k in planes)
                raise SSIError(f"-ssi_disp_ref {self.ref_text}: with -ssi_symmetry {sym} the footing's reference "
                               f"point must lie on the plane {'xy'[ax]} = 0")
        super().bind(mesh, regions, planes, h)

    def control_point(self, mesh, regions, planes):
        """The footing's centroid, whatever its reference point (which only says about which point the
        motion is told: it moved the wave's control point too, and every series shifted in time against
        the run without it; issue 44)."""
        from ..bem.input_motion import region_centroid
        return region_centroid(mesh, regions, planes)

    def correction(self, comm, prob, march):
        """Collective: the footing's step correction (``bem.input_motion.MasslessFooting``)."""
        from ..bem.input_motion import MasslessFooting
        return MasslessFooting(comm, prob, march)

    def describe(self):
        return (f"{self.name}: {self.elements.size} elements, unknown rigid motion about x_ref "
                f"({', '.join(f'{v:.6g}' for v in self.xref)}) m" if self.xref is not None else
                f"{self.name}: {self.elements.size} elements")


def rigid_motion(cfg, mesh):
    """The rigid motion the options describe (-ssi_disp_group and -ssi_disp_*), or None (no group, or
    an empty one); warns about -ssi_disp_* options that do nothing. SSIError on a bad vector or
    history, naming the option."""
    if not cfg.disp_group:
        for name in ("disp_value", "disp_rotation", "disp_ref"):
            if cfg.user_set(name):
                warn(f"-ssi_{name} is set but no -ssi_disp_group: nothing is prescribed")
        return None
    elems = mesh.select(cfg.disp_group)
    symmetry.check_box("-ssi_disp_group", cfg.disp_group, mesh.centres(), symmetry.parse(cfg.get("symmetry", "")))
    if not len(elems):
        return None
    try:
        hist = History(cfg.get("disp_history"), cfg.get("disp_t0"), cfg.get("disp_table"))
    except SSIError as exc:
        raise SSIError(f"-ssi_disp_history {cfg.get('disp_history')}: {exc}") from None
    if cfg.get("disp_rigid", "prescribed") == "massless":
        # (the options stay as given: a restart's key compares them)
        xref = parse_vector(cfg.disp_ref, "disp_ref") if cfg.user_set("disp_ref") else None
        return MasslessRigidFooting(elems, hist, xref, cfg.disp_group, name=f"-ssi_disp_group {cfg.disp_group}",
                                    ref_text=cfg.disp_ref)
    return PrescribedRigidMotion(elems, parse_vector(cfg.disp_value, "disp_value"),
                                 parse_vector(cfg.disp_rotation, "disp_rotation"), hist,
                                 parse_vector(cfg.disp_ref, "disp_ref"), name=f"-ssi_disp_group {cfg.disp_group}")
