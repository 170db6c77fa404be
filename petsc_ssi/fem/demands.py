r"""Storey demands of the structure every step: base shear, overturning moment and inter-storey
drift ratios (issue 28), an observer of the recorder (``io.recorder.Recorder``) and the output
group ``demands`` of the structure's output file.

Conventions (attributes of every dataset):

  base_shear          (V_x, V_y) [N]: the horizontal force the STRUCTURE EXERTS ON THE GROUND
                      through its base (the supports, the foundation soil), the foundation's own
                      inertia included: positive along +x when the structure, displaced along +x,
                      pushes the ground along +x; under static lateral loads it is their sum (the
                      engineers' base shear, Chopra's V_b); dynamically minus the sum of the
                      inertia forces m a of every node with its absolute acceleration (and of the
                      mass-proportional dashpots, see below). The same quantity with and without
                      SSI, so their peaks compare.
  overturning_moment  (M_x, M_y) [N m]: the moment vector (right-hand rule) of the same forces about
                      the reference point x_ref: M = sum (x - x_ref) x F (plus the nodal moments
                      of frame and shell supports); a lateral load F_x at height h above x_ref
                      gives M_y = +h F_x, a load F_y gives M_x = -h F_y.
  drift_ratio         (n_storeys, 2) [-]: storey i, between the levels z_i < z_{i+1}: the mean
                      horizontal displacement (u_x, u_y) of the structure's nodes within
                      -ssi_structure_level_tol of z_{i+1} minus that at z_i, divided by
                      z_{i+1} - z_i; then the pairs of structure receivers (lower:upper) of
                      -ssi_structure_drift_pairs: (u_upper - u_lower) / (z_upper - z_lower). The
                      displacements are those the run computes: relative to the moving base in a
                      fixed-base run (relative-motion form), total in a coupled run (a rocking
                      foundation's rigid rotation is part of the drift there).
  base_rotation       (theta_x, theta_y) [rad] of the lowest drift level (least-squares fit of its
                      nodes' u_z), and drift_ratio_deformation = drift_ratio - (theta_y, -theta_x):
                      the drift without the foundation's rocking (equal to drift_ratio on a fixed
                      base). With levels only.

Where the forces come from:

  fixed base (``-ssi_problem fem``)  the reactions at the base: the fixed dofs of the nodes at the
      lowest level of the fixed nodes (within the level tolerance); fixed dofs above it (symmetry
      planes, lateral supports) are not the base and are left out. The support's force on the
      structure at a fixed dof c is (K u)_c + m_c a_g(t) (u = 0 there, and the node moves with the
      ground: relative-motion form), so V = -sum_c [(K u^n)_c + m_c a_g(t_n)] over the base's x (y)
      (with Rayleigh's stiffness-proportional damping a1 K, whose dashpots act across the members,
      (K u^n)_c becomes (K (u^n + a1 v^n))_c)
      dofs and M = -R_c^T [K u^n + m a_g(t_n)], R_c the rigid rotation about x_ref restricted to
      the base's fixed dofs, a_g(t_n) the record's acceleration at t_n. With K symmetric the
      stiffness part is one linear functional g . u^n, g = -K e (formed once): exact at t_n for any
      integrator, and in a static solve V, M are the applied loads' resultants exactly (K
      annihilates the rigid motions). (A load put on a fixed dof goes into the support and is not
      counted.) Without the base nodes' inertia, -sum_c (K u^n)_c is the shear of the members at
      the base (columns): V plus the foundation's m a_g (V less its inertia force -m a_g). Dynamically the structure's
      equilibrium ties V to the inertia forces: the Green's-function scheme (trapezoidal free
      steps between velocity impulses, ``fem/integrators.py``) satisfies on the free dofs
          M (v^n - v^{n-1})/dt + C vbar + K ubar = fbar - alpha_m dt (f^{n-1} - f^n)/4,
      bars the means of steps n and n-1, f^n = -M iota ag^n the load of step n (ag^n the ground's
      mean acceleration over [t_n - dt/2, t_n + dt/2]); summed over the free x dofs (K's rows sum
      to zero over a rigid translation):
          (V^n + V^{n-1})/2 = -sum_free m [(v^n - v^{n-1})/dt + (ag^n + ag^{n-1})/2]
                              - alpha_m sum_free m [vbar + dt (ag^n - ag^{n-1})/4]
                              - sum_base m (a_g(t_n) + a_g(t_{n-1}))/2,
      minus the sum of the inertia forces with the absolute acceleration, minus the mass-
      proportional dashpots' forces (C = alpha_m M on the relative velocity: dashpots from each
      node to the moving ground, whose forces reach the ground without passing through the base;
      they are not in base_shear). tests/fem/test_demands.py checks this to round-off.
  coupled (``-ssi_problem ssi``)  the interface force of the step (the interface series'
      ``force_fe``, the soil's force on the structure, -M p, the foundation's inertia included;
      ``moment_fe`` about the origin):
      V = -force_fe[:2], M = -(moment_fe - x_ref x force_fe)[:2], with the force of step n as the
      coupling hands it over (implicit: the mean over (t_{n-1}, t_n]); zero at t = 0 (at rest).
      x_ref (auto): the interface's centroid at z = 0, moved onto the -ssi_symmetry planes.

A half (quarter) model gives the values of the modelled part (the mesh), not of the whole
structure. Each functional's owned part is a sparse row on its rank: one small reduction per
step (no field is gathered); rank 0 keeps the values and writes them.
"""
import numpy as np

from ..options import register, nonnegative
from ..petsc import SSIError, printf

G = "fem"

register("structure_drift_levels", "str", "", "m", "floor levels 'z0,z1,...' (increasing) of the inter-storey "
         "drift ratios: storey i = (mean (u_x, u_y) of the structure's nodes at z_{i+1} minus that at z_i) / "
         "(z_{i+1} - z_i), written every step to the group 'demands' of the structure's output", G)
register("structure_drift_pairs", "str", "", "", "storey drifts between structure receivers 'lower:upper;...' "
         "(indices into -ssi_receivers of fem runs, -ssi_structure_receivers of coupled runs, from 0): "
         "(u_upper - u_lower) / (z_upper - z_lower) along x and y", G)
register("structure_level_tol", "real", 0.01, "m", "a node belongs to a drift level (and a fixed node to the "
         "base) when its z lies within this distance of the level", G, validator=nonnegative)
register("structure_moment_ref", "str", "auto", "m", "reference point 'x,y,z' of the overturning moment; auto: "
         "the interface's centroid at z = 0 (coupled runs, on the -ssi_symmetry planes), the centroid of the "
         "base's fixed nodes (fixed-base runs)", G)

CONV_SHEAR = ("force the structure exerts on the ground through its base (the foundation's inertia included), "
              "x and y; = the sum of the lateral loads in a static case, minus the sum of the nodal inertia forces "
              "(absolute accelerations) dynamically; fixed base: minus the base's support reactions (K u + m a_g "
              "at the base's fixed dofs, + a1 K v with Rayleigh's stiffness-proportional damping a1 K) at t_n; coupled: minus the interface force of the step (the soil's force "
              "on the structure)")
CONV_MOMENT = ("moment vector (right-hand rule) about x and y of the forces the structure exerts on its base, "
               "about the reference point x_ref: M = sum (x - x_ref) x F; a lateral load F_x at height h gives "
               "M_y = +h F_x")
CONV_DRIFT = ("inter-storey drift ratio (upper level's mean horizontal displacement minus the lower's) / "
              "storey height, x and y; storeys of the levels first, then the receiver pairs; the displacements "
              "of the run (fixed base: relative to the base; coupled: total, the foundation's rocking included)")
CONV_ROT = ("rigid rotation (theta_x, theta_y) of the lowest drift level (right-hand rule), the least-squares fit "
            "u_z = theta_x (y - y_c) - theta_y (x - x_c) of its nodes; NaN about an axis the level's nodes do not "
            "span")
CONV_DEF = ("drift_ratio minus the lowest level's rigid rotation (theta_y, -theta_x): the storeys' deformation "
            "without the foundation's rocking")


def parse_levels(text):
    """'z0,z1,...' -> increasing levels (SSIError otherwise); '' -> []."""
    text = str(text or "").strip()
    if not text:
        return np.zeros(0)
    try:
        z = np.array([float(s) for s in text.replace(";", ",").split(",") if s.strip()])
    except ValueError:
        raise SSIError(f"-ssi_structure_drift_levels '{text}': expected levels 'z0,z1,...' in metres") from None
    if len(z) < 2 or np.any(np.diff(z) <= 0) or not np.all(np.isfinite(z)):
        raise SSIError(f"-ssi_structure_drift_levels '{text}': give at least two increasing levels (one storey)")
    return z


def parse_pairs(text, n_receivers, what):
    """'i:j;...' -> (P, 2) receiver indices (SSIError on a bad one)."""
    text = str(text or "").strip()
    if not text:
        return np.zeros((0, 2), np.int64)
    out = []
    for item in [s for s in text.replace(",", ";").split(";") if s.strip()]:
        try:
            i, j = (int(s) for s in item.split(":"))
        except ValueError:
            raise SSIError(f"-ssi_structure_drift_pairs '{item}': expected 'lower:upper' receiver indices") from None
        for k in (i, j):
            if not 0 <= k < n_receivers:
                raise SSIError(f"-ssi_structure_drift_pairs '{item}': receiver {k} does not exist ({what} gives "
                               f"{n_receivers} receiver(s), indices 0..{n_receivers - 1})")
        out.append((i, j))
    return np.array(out, np.int64)


def parse_ref(text):
    text = str(text or "auto").strip()
    if text == "auto":
        return None
    try:
        p = np.array([float(s) for s in text.split(",")])
    except ValueError:
        p = np.zeros(0)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise SSIError(f"-ssi_structure_moment_ref '{text}': expected 'x,y,z' in metres or auto")
    return p


class DemandSpec:
    """Replicated, before any assembly: the drift levels and their nodes, the receiver pairs, the
    base (fixed-base runs) and the moment's reference point, every input checked (SSIError).

    ``model``: the structure's model (``fem.model.Model``, assembled or not); ``receivers_option``
    names the option of its receivers; ``base``: 'reactions' (fixed base) or 'interface'
    (coupled); ``ref_auto``: the reference point when the option says auto (coupled runs)."""

    def __init__(self, cfg, model, receivers_option, base="reactions", ref_auto=None):
        mesh, dm = model.mesh, model.dofmap
        z = mesh.coords[:, 2]
        self.tol = float(cfg.get("structure_level_tol", 0.01))
        self.levels = parse_levels(cfg.get("structure_drift_levels", ""))
        self.level_nodes = []
        for zl in self.levels:
            nodes = np.nonzero(np.abs(z - zl) <= self.tol)[0]
            if nodes.size == 0:
                zs = np.unique(np.round(z, 9))
                near = zs[np.argsort(np.abs(zs - zl), kind="stable")[:3]]
                raise SSIError(f"-ssi_structure_drift_levels: no node of the structure within "
                               f"{self.tol:g} m (-ssi_structure_level_tol) of z = {zl:g} m (the nearest node "
                               f"levels: {', '.join(f'{v:g}' for v in near)} m)")
            self.level_nodes.append(nodes)
        for k in range(len(self.level_nodes) - 1):
            both = np.intersect1d(self.level_nodes[k], self.level_nodes[k + 1])
            if both.size:                 # the storey's two means share nodes: its drift is 0 or too small
                raise SSIError(f"-ssi_structure_drift_levels: the levels z = {self.levels[k]:g} and "
                               f"{self.levels[k + 1]:g} m share {both.size} node(s) within -ssi_structure_level_tol "
                               f"{self.tol:g} m (e.g. z = {z[both[0]]:g} m): their drift would be 0 every step; give "
                               f"levels more than 2 x the tolerance apart, or a smaller -ssi_structure_level_tol")
        self.pairs = parse_pairs(cfg.get("structure_drift_pairs", ""), len(model.receiver_nodes), receivers_option)
        self.pair_nodes = model.receiver_nodes[self.pairs] if len(self.pairs) else np.zeros((0, 2), np.int64)
        for (i, j), (a, b) in zip(self.pairs, self.pair_nodes):
            if not z[b] - z[a] > self.tol:
                raise SSIError(f"-ssi_structure_drift_pairs {i}:{j}: the upper receiver's node (z = {z[b]:g} m) "
                               f"must lie above the lower's (z = {z[a]:g} m) by more than {self.tol:g} m")
        self.pair_h = (z[self.pair_nodes[:, 1]] - z[self.pair_nodes[:, 0]]) if len(self.pairs) else np.zeros(0)
        self.base = base
        ref = parse_ref(cfg.get("structure_moment_ref", "auto"))
        self.base_dofs = np.zeros(0, np.int64)
        self.n_above = 0
        if base == "reactions":
            fixed = np.asarray(model.fixed, np.int64)
            if fixed.size:
                node = np.searchsorted(dm.offset, fixed, side="right") - 1
                zb = z[node].min()
                at = np.abs(z[node] - zb) <= self.tol
                self.base_dofs, self.n_above, self.z_base = fixed[at], int((~at).sum()), zb
                if ref is None:
                    bn = np.unique(node[at])
                    ref = np.r_[mesh.coords[bn, :2].mean(axis=0), zb]
        elif ref is None:
            ref = np.asarray(ref_auto, float)
        self.ref = np.zeros(3) if ref is None else np.asarray(ref, float)
        self.has_base = base == "interface" or self.base_dofs.size > 0

    @property
    def n_storeys(self):
        return max(len(self.levels) - 1, 0) + len(self.pairs)

    @property
    def any(self):
        return self.has_base or self.n_storeys > 0

    def storey_bounds(self):
        """(n_storeys, 2) z of each storey's lower and upper level [m]."""
        lv = np.c_[self.levels[:-1], self.levels[1:]] if len(self.levels) else np.zeros((0, 2))
        return lv


class Demands:
    """Collective: the observer of the recorder that keeps the demands of every step (module
    docstring). ``spec``: a DemandSpec; ``model``: the assembled model (K for the reactions);
    ``what``: '[fem]' or '[ssi]' for the start-up line; ``a1``: the stiffness-proportional damping
    (C = alpha_m M + a1 K, -ssi_fem_rayleigh*): its dashpots act across the members, so at the base
    the support also takes a1 (K v)_c, added to the reactions (g . (u + a1 v))."""

    def __init__(self, spec, model, comm, what="[fem]", ground=None, a1=0.0):
        self.spec, self.comm, self.rank = spec, comm, comm.getRank()
        self.a1 = float(a1)
        self.ground = ground                      # t -> (3,) the base's acceleration [m/s^2] (support motion)
        self.Cg = np.zeros((4, 3))
        dm = model.dofmap
        coords = model.mesh.coords
        self.funcs = []                           # Vecs g: value = g . u
        for nodes in spec.level_nodes:            # the level's mean u_x, u_y
            t = dm.translation_dofs(nodes)
            for c in range(2):
                a = np.zeros(dm.size)
                a[t[:, c]] = 1.0 / len(nodes)
                self.funcs.append(dm.vec_from_global(a))
        for (a_node, b_node), h in zip(spec.pair_nodes, spec.pair_h):
            ta, tb = dm.translation_dofs([a_node])[0], dm.translation_dofs([b_node])[0]
            for c in range(2):
                a = np.zeros(dm.size)
                a[tb[c]] += 1.0 / h
                a[ta[c]] -= 1.0 / h
                self.funcs.append(dm.vec_from_global(a))
        self.rot_ok = np.zeros(2, bool)
        if len(spec.levels):                      # the lowest level's rigid rotation (theta_x, theta_y) from u_z
            nodes = spec.level_nodes[0]
            tz = dm.translation_dofs(nodes)[:, 2]
            xy = coords[nodes, :2] - coords[nodes, :2].mean(axis=0)
            for c, (col, sign) in enumerate(((1, 1.0), (0, -1.0))):     # u_z = theta_x y - theta_y x
                den = float((xy[:, col] ** 2).sum())
                a = np.zeros(dm.size)
                if den > (1e-9 * max(np.abs(coords).max(), 1.0)) ** 2:
                    a[tz] = sign * xy[:, col] / den
                    self.rot_ok[c] = True
                self.funcs.append(dm.vec_from_global(a))
        self.n_drift_funcs = len(self.funcs)
        if spec.base == "reactions" and spec.base_dofs.size:
            R = dm.rigid_body_modes(coords, centre=spec.ref)
            mask = np.zeros(dm.size)
            mask[spec.base_dofs] = 1.0
            for k in (0, 1, 3, 4):                # V_x, V_y, M_x, M_y: g = -K (R_k on the base's dofs)
                e = dm.vec_from_global(R[:, k] * mask)
                g = e.duplicate()
                model.K.mult(e, g)
                g.scale(-1.0)
                e.destroy()
                self.funcs.append(g)
            # the base nodes' inertia m a_g (they move with the ground): -R_k^T (m iota_c) per axis c
            r0, r1 = dm.r0, dm.r1
            mloc = model.m.getArray(readonly=True)
            tb = dm.translation_dofs(np.arange(model.mesh.n_nodes))
            loc = np.zeros((4, 3))
            for c in range(3):
                iota = np.zeros(dm.size)
                d = tb[:, c][np.isin(tb[:, c], spec.base_dofs)]
                iota[d] = 1.0
                w = iota[r0:r1] * mloc
                loc[:, c] = -(R[r0:r1][:, [0, 1, 3, 4]] * w[:, None]).sum(axis=0)
            from mpi4py import MPI
            comm.tompi4py().Allreduce(loc, self.Cg, op=MPI.SUM)
        from scipy.sparse import csr_matrix            # the owned part of every functional, (n_func, n_local)
        rows = [g.getArray(readonly=True) for g in self.funcs]
        self.G = csr_matrix(np.array(rows) if rows else np.zeros((0, dm.n_local)))
        for g in self.funcs:
            g.destroy()
        self.funcs = []
        self.mpi = comm.tompi4py()
        self.t, self.values = [], []
        if spec.base == "reactions" and spec.base_dofs.size:
            printf(f"{what} demands: base shear and overturning moment from the reactions of the "
                   f"{spec.base_dofs.size} fixed dof(s) at the base z = {spec.z_base:g} m"
                   + (f" ({spec.n_above} fixed dof(s) above it, e.g. symmetry planes, are not the base)"
                      if spec.n_above else "")
                   + ", moments about ({:g}, {:g}, {:g}) m".format(*spec.ref))
        elif spec.base == "interface":
            printf(f"{what} demands: base shear and overturning moment from the interface force, moments about "
                   "({:g}, {:g}, {:g}) m".format(*spec.ref))
        if spec.n_storeys:
            printf(f"{what} demands: drift ratios of {spec.n_storeys} storey(s)"
                   + (" (levels " + ", ".join(f"{z:g}" for z in spec.levels) + " m: "
                      + ", ".join(str(len(n)) for n in spec.level_nodes) + " nodes)" if len(spec.levels) else ""))

    # ------------------------------------------------------------ the recorder's protocol
    def initial(self, t, step, write=False):
        if step.get("structure") is not None:
            self.record(t, step["structure"][0])            # at rest: no interface force yet

    def observe(self, n, t, step):
        s = step.get("structure")
        if s is None:
            return
        self.record(t, s[0], step.get("interface"), v=s[1] if len(s) > 1 else None)

    def record(self, t, u, interface=None, v=None):
        """Collective: the demands of the state u (velocity v: the stiffness-proportional dashpots'
        share of the reactions, with a1 > 0) at time t (``interface``: the coupled step's record
        with force_fe, moment_fe; None at t = 0 or in a fixed-base run)."""
        vals = np.zeros(self.G.shape[0])
        if vals.size:                             # one small reduction (no field is gathered)
            from mpi4py import MPI
            x = u.getArray(readonly=True)
            loc = self.G @ x
            if self.a1 and v is not None and self.G.shape[0] > self.n_drift_funcs:
                loc[self.n_drift_funcs:] += self.a1 * (self.G[self.n_drift_funcs:] @ v.getArray(readonly=True))
            self.mpi.Allreduce(loc, vals, op=MPI.SUM)
        if self.ground is not None and self.spec.base == "reactions" and self.spec.base_dofs.size:
            vals[self.n_drift_funcs:] += self.Cg @ np.asarray(self.ground(t), float)
        if self.spec.base == "interface":
            F = np.zeros(3) if interface is None else np.asarray(interface["force_fe"], float)
            M0 = np.zeros(3) if interface is None else np.asarray(interface["moment_fe"], float)
            Mref = M0 - np.cross(self.spec.ref, F)
            vals = np.r_[vals, -F[:2], -Mref[:2]]
        if self.rank == 0:
            self.t.append(float(t))
            self.values.append(vals)

    def state(self, n_times=None):
        if self.rank != 0:
            return {}
        return {"demands_t": np.asarray(self.t, float), "demands_values": np.asarray(self.values, float)}

    def restore(self, s, n=None):
        """The series of a checkpoint; one written before the demands existed leaves the steps up
        to it unknown (NaN, with a warning)."""
        if "demands_t" not in s:
            from ..petsc import warn
            warn("the checkpoint holds no storey demands (written by an older version): the demands of the "
                 "steps up to it are NaN in the output", self.comm)
            t = np.r_[0.0, np.asarray(s["times"], float)]
            width = self.G.shape[0] + (4 if self.spec.base == "interface" else 0)
            s = {"demands_t": t, "demands_values": np.full((len(t), width), np.nan)}
        if self.rank != 0:
            return
        self.t = [float(x) for x in s["demands_t"]]
        self.values = [np.asarray(v, float) for v in s["demands_values"]]

    def destroy(self):
        self.G = self.G[:0]

    # ------------------------------------------------------------ output
    def arrays(self):
        """Rank 0: the series (t, base_shear, overturning_moment, drift_ratio) without the peaks."""
        sp = self.spec
        t = np.asarray(self.t, float)
        v = np.asarray(self.values, float).reshape(len(t), -1)
        out = {"t": t}
        nd, k = self.n_drift_funcs, 0
        drift = []
        if len(sp.levels):
            nl = len(sp.levels)
            means = v[:, :2 * nl].reshape(len(t), nl, 2)
            h = np.diff(sp.levels)
            drift.append((means[:, 1:] - means[:, :-1]) / h[None, :, None])
            k = 2 * nl
        if len(sp.pairs):
            drift.append(v[:, k:k + 2 * len(sp.pairs)].reshape(len(t), len(sp.pairs), 2))
            k += 2 * len(sp.pairs)
        if drift:
            out["drift_ratio"] = np.concatenate(drift, axis=1)
        if len(sp.levels):
            rot = v[:, k:k + 2].copy()
            rot[:, ~self.rot_ok] = np.nan
            out["base_rotation"] = rot
            # a rigid rotation theta moves a node by theta x r: u_x = theta_y z, u_y = -theta_x z
            rigid = np.stack([rot[:, 1], -rot[:, 0]], axis=-1)[:, None, :]
            out["drift_ratio_deformation"] = out["drift_ratio"] - rigid
        if sp.has_base:
            out["base_shear"] = v[:, nd:nd + 2]
            out["overturning_moment"] = v[:, nd + 2:nd + 4]
        return out

    def groups(self, steps=None, times=None):
        """The recorder's protocol (``io.recorder``): {'demands': ``group()``} (None off rank 0)."""
        return {"demands": self.group() if self.rank == 0 else None}

    def group(self):
        """Rank 0: the output group 'demands' {name: (array, unit, attrs)} (series, peaks, levels)."""
        sp = self.spec
        a = self.arrays()
        t = a["t"]
        g = {"t": (t, "s", {"convention": "time of each step t_n"})}
        desc = {"base_shear": ("N", CONV_SHEAR), "overturning_moment": ("N m", CONV_MOMENT),
                "drift_ratio": ("m/m", CONV_DRIFT), "base_rotation": ("rad", CONV_ROT),
                "drift_ratio_deformation": ("m/m", CONV_DEF)}
        for name, (unit, conv) in desc.items():
            if name not in a:
                continue
            x = a[name]
            attrs = {"convention": conv}
            if name in ("base_shear", "overturning_moment"):
                attrs["source"] = ("support reactions at t_n (fixed base)" if sp.base == "reactions" else
                                   "interface force of the step (coupled; implicit: the mean over (t_{n-1}, t_n])")
            g[name] = (x, unit, attrs)
            pk, pt = peaks(t, x)
            g["peak_" + name] = (pk, unit, {"convention": "max over the steps of |" + name + "| per component"})
            g["peak_" + name + "_time"] = (pt, "s", {"convention": "the first time of each peak"})
        if len(sp.levels):
            g["levels"] = (sp.levels, "m", {"convention": "floor levels z of -ssi_structure_drift_levels"})
            g["level_node_count"] = (np.array([len(n) for n in sp.level_nodes]), "1",
                                     {"convention": "structure nodes within -ssi_structure_level_tol of each level"})
        if len(sp.pairs):
            g["pairs"] = (sp.pairs, "1", {"convention": "receiver indices (lower, upper) of the pair storeys"})
            g["pair_height"] = (sp.pair_h, "m", {"convention": "z_upper - z_lower of each pair's nodes"})
        if sp.has_base:
            g["reference_point"] = (sp.ref, "m", {"convention": "x_ref of overturning_moment"})
        return g


def peaks(t, x):
    """(max over axis 0 of |x|, the first time of it) for a series x (K, ...), NaN steps skipped."""
    x = np.asarray(x, float)
    if x.shape[0] == 0:
        return np.zeros(x.shape[1:]), np.zeros(x.shape[1:])
    a = np.abs(x)
    i = np.argmax(np.where(np.isnan(a), -1.0, a), axis=0)     # unknown (NaN) steps skipped
    return np.take_along_axis(a, i[None], axis=0)[0], np.asarray(t, float)[i]
