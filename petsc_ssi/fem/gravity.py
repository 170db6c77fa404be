"""The structure's self-weight as a static case beside the earthquake (issue 43, ``-ssi_fem_gravity g``).

One static solve before the steps: K u_G = f_G, f_G = -g m_z e_z on every translation z dof (m_z the
lumped mass of the node: the elements' own mass, the parts' added masses and the point masses, the
mass the dynamics uses), the fixed dofs held at zero. The structure is linear, so the earthquake's
response E(t) (member forces, reactions: the run's increments from the unloaded state) superposes on
the gravity state G; the combined envelopes are, component by component,

    G + max_t E(t)   and   G + min_t E(t)

(the signed extremes over every step, the state at rest t = 0 included: the combined maximum is never
below G, nor the minimum above it). This is the 'G + E' of the design codes with factors 1; other
factors scale the two parts of the written datasets.

Reactions of the gravity case: r = K u_G - f_G on the fixed dofs (the forces the supports exert on the
structure: a node's own weight on a fixed dof goes straight into its support), and the resultant the
structure exerts on its supports, base_force = -sum r (its z component is -W, W = g sum m_z the
weight), base_moment about the demands' reference point (the forces' moments, right-hand rule, as
``fem/demands.py``'s overturning moment).

Output (the structure's file): group ``gravity`` (g, weight, base_force, base_moment, reactions per
fixed node, and with storey demands the base shear and overturning moment of G combined with the
earthquake's extremes), and ``forces/<part>_gravity``, ``_max``, ``_min``, ``_gravity_plus_max``,
``_gravity_plus_min`` beside the member force envelope (``fem/forces.py``).

The fixed base only (``-ssi_problem fem`` and ``petsc-ssi static``): in a coupled run the soil's
static response is not modelled (the time-domain BEM gives the dynamic increment only) and the option
is refused there; the contact preload (``-ssi_contact_preload weight``) stands in for the weight's
pressure at the interface.
"""
import numpy as np

from ..petsc import printf, warn

from .forces import COMBINATION  # noqa: F401  (the rule, stated with the member forces; the option: fem/options.py)

# A structure that moves more than this fraction of its size under its own weight has a wrong unit (E in GPa
# sagged an engineer's building 1.5 km) or a mechanism: real structures move millimetres to centimetres.
SAG_WARN = 0.01


def gravity_load(model, g):
    """Collective: the Vec f_G = -g m_z on every translation z dof (fixed ones included) [N]."""
    dm = model.dofmap
    f = model.m.duplicate()
    f.zeroEntries()
    tz = dm.translation_dofs(np.arange(model.mesh.n_nodes))[:, 2]
    tz = tz[(tz >= dm.r0) & (tz < dm.r1)] - dm.r0
    a = f.getArray()
    a[tz] = -g * model.m.getArray(readonly=True)[tz]
    return f


class GravityCase:
    """Collective: the static self-weight case of an assembled ``model`` under gravity ``g`` [m/s^2]:
    ``u`` (Vec, K u = f_G with the fixed dofs held), ``weight`` [N], the reactions (replicated) and
    their resultant. ``ref``: the point of the moments (default: the centroid of the fixed nodes at
    their lowest level, or the origin)."""

    def __init__(self, cfg, model, comm, g, ref=None):
        from .static import static_solve
        from .integrators import near_null_args
        from mpi4py import MPI
        PETSc = __import__("petsc4py.PETSc", fromlist=["PETSc"])
        self.g = float(g)
        dm = model.dofmap
        f = gravity_load(model, self.g)
        fixed = np.asarray(model.fixed, np.int64)
        own = fixed[(fixed >= dm.r0) & (fixed < dm.r1)] - dm.r0
        b = f.copy()
        b.getArray()[own] = 0.0                  # the fixed dofs' own weight goes into their supports
        coords, near = near_null_args(cfg.fem_solver, model)
        self.u = static_solve(model.K, b, model.fixed, model.mesh.coords, solver=cfg.fem_solver, dofmap=dm,
                              near_null=near if coords is None else PETSc.NullSpace().createRigidBody(coords))
        b.destroy()
        mpi = comm.tompi4py()
        tz = dm.translation_dofs(np.arange(model.mesh.n_nodes))[:, 2]
        tz = tz[(tz >= dm.r0) & (tz < dm.r1)] - dm.r0
        mz = model.m.getArray(readonly=True)[tz]
        held = np.isin(tz + dm.r0, fixed)
        self.mass = mpi.allreduce(float(mz.sum()), op=MPI.SUM)
        self.weight = self.g * self.mass
        self.free_weight = self.g * mpi.allreduce(float(mz[~held].sum()), op=MPI.SUM)
        r = f.duplicate()
        model.K.mult(self.u, r)
        r.axpy(-1.0, f)                           # r = K u - f: the supports' forces on the structure
        loc = np.zeros(len(fixed))
        sel = (fixed >= dm.r0) & (fixed < dm.r1)
        loc[sel] = r.getArray(readonly=True)[fixed[sel] - dm.r0]
        self.reaction = np.zeros(len(fixed))
        mpi.Allreduce(loc, self.reaction, op=MPI.SUM)
        r.destroy()
        f.destroy()
        node = np.searchsorted(dm.offset, fixed, side="right") - 1
        k = fixed - dm.offset[node]
        k = np.where(k >= 6, k - 3, k)            # a released rotation triple sums into the node's rotation
        self.nodes = np.unique(node)
        self.reactions = np.zeros((len(self.nodes), 6))
        np.add.at(self.reactions, (np.searchsorted(self.nodes, node), k), self.reaction)
        coords_all = model.mesh.coords
        if ref is None:
            ref = np.zeros(3)
            if len(self.nodes):
                z = coords_all[self.nodes, 2]
                low = self.nodes[np.abs(z - z.min()) <= 1e-9 * max(1.0, np.abs(z).max())]
                ref = np.r_[coords_all[low, :2].mean(axis=0), z.min()]
        self.ref = np.asarray(ref, float)
        x = coords_all[self.nodes] - self.ref
        Fn, Mn = -self.reactions[:, :3], -self.reactions[:, 3:]       # on the supports
        self.base_force = Fn.sum(axis=0)
        self.base_moment = np.cross(x, Fn).sum(axis=0) + Mn.sum(axis=0)
        self.coords = coords_all[self.nodes]
        umax = self.u.norm(PETSc.NormType.INFINITY)
        tr = dm.translation_dofs(np.arange(model.mesh.n_nodes)).ravel()
        tr = tr[(tr >= dm.r0) & (tr < dm.r1)] - dm.r0
        ua = self.u.getArray(readonly=True)
        sag = mpi.allreduce(float(np.abs(ua[tr]).max()) if tr.size else 0.0, op=MPI.MAX)
        size = float(np.linalg.norm(np.ptp(coords_all, axis=0))) if len(coords_all) else 0.0
        if size > 0 and sag > SAG_WARN * size:
            warn(f"the structure moves {sag:.3g} m under its own weight, {100 * sag / size:.3g} % of its size "
                 f"({size:.3g} m across): a wrong unit (E in N/m^2, sections and thicknesses in m, densities in "
                 "kg/m^3) or a support missing; the run goes on as given", comm)
        printf(f"[fem] gravity {self.g:g} m/s^2 along -z: weight {self.weight:.6g} N (mass {self.mass:.6g} kg); "
               f"static solve: max |u_i| = {umax:.3e}; reactions of the {len(self.nodes)} supported node(s) sum to "
               f"{-self.base_force[2]:.6g} N up; combined with the earthquake as {COMBINATION.split(':')[0]}")

    def group(self, demands=None):
        """Rank 0: the output group 'gravity' {name: (array, unit, attrs)}; ``demands``: the storey
        demands' arrays (base_shear, overturning_moment series) to combine with the gravity case's."""
        out = {"g": (np.float64(self.g), "m/s^2", {"convention": "gravity along -z"}),
               "weight": (np.float64(self.weight), "N", {"convention": "g times the structure's lumped mass (every "
                                                                       "node, the supported ones included)"}),
               "free_weight": (np.float64(self.free_weight), "N",
                               {"convention": "g times the lumped mass on the free z translations: the weight the "
                                              "members carry into the supports (the rest sits on them)"}),
               "base_force": (self.base_force, "N", {"convention": "force (x, y, z) the structure exerts on its "
                                                                   "supports under its self-weight (z: -weight)"}),
               "base_moment": (self.base_moment, "N m", {"convention": "moment (x, y, z) of those forces about "
                                                                       "reference_point (right-hand rule)"}),
               "reference_point": (self.ref, "m", {"convention": "point of base_moment"}),
               "reactions": (self.reactions, "N, N, N, N m, N m, N m",
                             {"convention": "per supported node (reaction_nodes): the force and moment (Fx, Fy, Fz, "
                                            "Mx, My, Mz) the support exerts on the structure, r = K u_G - f_G on the "
                                            "fixed dofs (0 on free dofs)"}),
               "reaction_nodes": (self.nodes, "1", {"convention": "0-based node indices (coordinates rows)"}),
               "reaction_coordinates": (self.coords, "m", {"convention": "the supported nodes' x, y, z"})}
        if demands:
            ref = demands.get("reference_point")
            for name, gval in (("base_shear", self.base_force[:2]), ("overturning_moment", None)):
                if name not in demands:
                    continue
                unit = "N" if name == "base_shear" else "N m"
                if gval is None:                   # G's moment about the demands' own reference point
                    dx = self.ref - (np.asarray(ref, float) if ref is not None else self.ref)
                    gval = (self.base_moment + np.cross(dx, self.base_force))[:2]
                e = np.asarray(demands[name], float)
                ok = ~np.isnan(e).any(axis=1)
                e = e[ok] if ok.any() else np.zeros((1, 2))
                attrs = {"convention": f"the gravity case's {name} (x, y) plus the earthquake's signed extreme over "
                                       "the steps, as demands/" + name, "combination": COMBINATION}
                out[f"{name}_gravity"] = (np.asarray(gval, float), unit, {"convention": f"{name} of the gravity "
                                                                                        "case alone (x, y)"})
                out[f"{name}_gravity_plus_max"] = (gval + e.max(axis=0), unit, attrs)
                out[f"{name}_gravity_plus_min"] = (gval + e.min(axis=0), unit, attrs)
        return out

    def destroy(self):
        self.u.destroy()


def gravity_case(cfg, model, comm, ref=None):
    """Collective: the GravityCase of -ssi_fem_gravity, or None when it is 0 (the model assembled)."""
    g = float(cfg.get("fem_gravity", 0.0) or 0.0)
    return GravityCase(cfg, model, comm, g, ref=ref) if g > 0 else None
