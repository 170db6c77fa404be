"""2-node 3D frame element: shear-flexible (Timoshenko) beam, 6 dofs per node.

Local axes and sign conventions
-------------------------------
x' runs from node 0 to node 1 (length L). z' is the part of the part's
``orientation`` vector v normal to x', normalised: the depth direction of the
section (a beam's "up"). y' = z' x x', so (x', y', z') is right-handed. The
rows of the 3x3 rotation Lam are x', y', z' in global components, and a local
vector is u' = Lam u. The section constants are

  Iy = int z'^2 dA   bending in the x'-z' plane (deflection w along z')
  Iz = int y'^2 dA   bending in the x'-y' plane (deflection v along y')
  J                  St-Venant torsion constant (``rect_section`` for rectangles)

Local dofs per node (u, v, w, tx, ty, tz): translations along and small
rotations about x', y', z', right-handed. For the section rotations this gives
tz = dv/dx' - gamma_y and ty = -(dw/dx' - gamma_z) (gamma: shear strains), so
the bending coupling terms of the x'-z' plane carry the opposite sign to those
of the x'-y' plane. The global dofs (ux, uy, uz, rx, ry, rz) are about the
GLOBAL axes (base.py): with T = blockdiag(Lam, Lam, Lam, Lam) (12 x 12),
K = T^T k T and u_local = T u_global.

Stiffness: exact Timoshenko beam
--------------------------------
Axial E A / L, St-Venant torsion G J / L (no warping). Bending: the static
stiffness of a prismatic Timoshenko beam, which is exact (not an
approximation) for loads applied at the nodes. Derivation, x'-y' plane:
a cantilever of length L (fixed at node 0) under a tip shear P and a tip
moment M has the flexibility

  [v ]   [ L^3/(3 E Iz) + L/(G As)   L^2/(2 E Iz) ] [P]
  [tz] = [ L^2/(2 E Iz)              L  /(E Iz)   ] [M],   As = shear_factor * area.

Its inverse is E Iz / ((1 + phi_y) L^3) [[12, -6L], [-6L, (4 + phi_y) L^2]]
with phi_y = 12 E Iz / (G As L^2); equilibrium (rigid-body modes) fills the
remaining rows, giving the 4 x 4 bending block on (v0, tz0, v1, tz1)

  E Iz / ((1 + phi_y) L^3) [[ 12,  6L,          -12,  6L        ],
                            [ 6L,  (4+phi_y)L^2, -6L, (2-phi_y)L^2],
                            [-12, -6L,           12, -6L        ],
                            [ 6L,  (2-phi_y)L^2, -6L, (4+phi_y)L^2]]

and the same with Iy, phi_z = 12 E Iy / (G As L^2) and the signs of the 6L
terms flipped on (w0, ty0, w1, ty1). This is the element of Przemieniecki,
"Theory of Matrix Structural Analysis" (McGraw-Hill 1968, sec. 5.6) and of
McGuire, Gallagher and Ziemian, "Matrix Structural Analysis" (2nd ed., Wiley
2000, ch. 4 and 5). Equivalently, it is the element with the interdependent
(cubic deflection, quadratic rotation) interpolation that solves the
homogeneous Timoshenko equations exactly (Reddy, "On locking-free shear
deformable beam finite elements", CMAME 149, 1997). Why this formulation:

  * exact for nodal loads on a straight prismatic member, so one element per
    member is enough for statics and frame meshes need no refinement;
  * no shear locking: phi -> 0 as the shear area grows (slender members), and
    the matrix tends smoothly to the Euler-Bernoulli (Hermite cubic) one; an
    equal-order linear Timoshenko element would lock;
  * shear_factor = 0 means "no shear deformation": phi = 0, Euler-Bernoulli.

The same shear area As = shear_factor * area is used in both planes (one
``shear_factor`` per part; 5/6 is the rectangle's value, Cowper, "The shear
coefficient in Timoshenko's beam theory", J. Appl. Mech. 33, 1966).

Lumped mass
-----------
HRZ lumping (Hinton, Rock and Zienkiewicz, "A note on mass lumping and related
processes in the finite element method", Earthquake Eng. Struct. Dyn. 4, 1976):
keep the diagonal of the consistent mass and scale it so that the
translational diagonal sums to the element mass. With m = rho A + added_mass
(kg/m), the consistent cubic-Hermite bending mass m L / 420 [[156, 22L, 54,
-13L], [22L, 4L^2, 13L, -3L^2], ...] has translational diagonal sum 312 m L /
420, so the scale is 420 / 312 and per node

  translations (all three)    m L / 2
  bending rotations ty, tz    m L^3 / 78  (= 4 L^2 m L / 420 * 420 / 312)
                              + rho_r I L / 2   (section rotary inertia, I = Iy for ty, Iz for tz)
  torsion tx                  rho_r (Iy + Iz) L / 2   (polar moment of the section)

with rho_r = rho + added_mass / area: the non-structural mass is taken to be
distributed over the section like the structural mass (same radius of
gyration). With added_mass = 0 these are rho I L / 2 and rho (Iy + Iz) L / 2;
including it keeps the torsional mass positive when rho = 0 and all the mass is
in added_mass. Every local diagonal entry is > 0 when area, Iy, Iz > 0 and
rho A + added_mass > 0 (``check``).

In global dofs the lumped rotational mass R = Lam^T diag(local) Lam of a node
is not diagonal for a skew member; the kernel keeps its diagonal,
R_ii = sum_p Lam_pi^2 d_p. This is exact for members along a global axis (Lam a
signed permutation), conserves the trace (sum_i Lam_pi^2 = 1) and stays >= the
smallest local entry, so it is > 0 on every dof. The translational block m L/2
times the identity is invariant, so the translational masses are always exact.

``stiffness_reference`` builds the same matrices one cell at a time, entry by
entry from the textbook table, with T written out explicitly and the local
axes from cross products (y' = v x x' / |v x x'|, z' = x' x y'), and is what
the vectorised ``stiffness`` is tested against.
"""
import numpy as np

from . import register
from .base import ElementType
from ...petsc import SSIError

# local dof order per node: u v w tx ty tz  (node-major, 6 a + k)
_U, _V, _W, _TX, _TY, _TZ = range(6)
END_FORCES = tuple(f"{c}_{e}" for e in "ij" for c in ("N", "V2", "V3", "T", "M2", "M3"))
END_FORCE_UNITS = ("N", "N", "N", "N m", "N m", "N m") * 2

# lambda(5) = sum over odd n of n^-5 = (1 - 2^-5) zeta(5)
_LAMBDA5 = 31.0 / 32.0 * 1.0369277551433699263


def rect_section(b, h):
    """Section constants of a solid b x h rectangle: dict(area, Iy, Iz, J).

    b is the width along y', h the depth along z' (the orientation vector):
    Iy = b h^3 / 12 (bending in the x'-z' plane), Iz = h b^3 / 12. J is the
    St-Venant torsion constant from the exact series (Timoshenko and Goodier,
    "Theory of Elasticity", 3rd ed., sec. 109), a >= c the long and short sides,

      J = a c^3 / 3 [1 - (192 / pi^5) (c / a) sum_{n odd} tanh(n pi a / (2 c)) / n^5].

    The series is summed as sum (tanh - 1) / n^5 over n = 1, 3, ..., 49 (the
    terms beyond n = 23 are below 1e-30) plus sum_{n odd} n^-5 = (31/32) zeta(5),
    so J is exact to round-off. (Roark's approximation a c^3 [1/3 - 0.21 (c/a)
    (1 - c^4 / (12 a^4))] is within 0.5 % of it for every aspect ratio,
    worst near a / c = 1.14.)
    """
    b, h = float(b), float(h)
    if not (b > 0 and h > 0):
        raise ValueError(f"rect_section: b and h must be > 0 (got b={b}, h={h})")
    a, c = max(b, h), min(b, h)
    n = np.arange(1, 50, 2, dtype=float)
    s = np.sum((np.tanh(n * np.pi * a / (2 * c)) - 1.0) / n ** 5) + _LAMBDA5
    J = a * c ** 3 / 3.0 * (1.0 - 192.0 / np.pi ** 5 * (c / a) * s)
    return dict(area=b * h, Iy=b * h ** 3 / 12.0, Iz=h * b ** 3 / 12.0, J=float(J))


def _orientation(props, n_cells):
    """The orientation vector of every cell, (E, 3): props.orientation is one
    3-vector (broadcast) or one per cell."""
    v = np.asarray(props.orientation, dtype=float)
    return np.broadcast_to(v, (n_cells, 3))


def _geometry(X, props):
    """Lengths L (E,) and rotations Lam (E, 3, 3), rows x', y', z' (global
    components), by Gram-Schmidt of the orientation against the axis. No checks."""
    X = np.asarray(X, dtype=float)
    d = X[:, 1] - X[:, 0]
    L = np.sqrt(np.einsum("ei,ei->e", d, d))
    ex = d / L[:, None]
    v = _orientation(props, X.shape[0])
    ez = v - np.einsum("ei,ei->e", v, ex)[:, None] * ex
    ez /= np.linalg.norm(ez, axis=1)[:, None]
    ey = np.cross(ez, ex)
    return L, np.stack([ex, ey, ez], axis=1)


def _phi(E, G, I, shear_factor, area, L):
    """Shear flexibility ratio 12 E I / (G As L^2); 0 (Euler-Bernoulli) for shear_factor = 0."""
    if shear_factor == 0:
        return np.zeros_like(L)
    return 12.0 * E * I / (G * shear_factor * area * L ** 2)


def _patterns():
    """Constant 12 x 12 matrices P_c with k_local = sum_c C_c P_c, for the per-cell
    coefficients C = (EA/L, GJ/L, c_y [12, 6L, (4+phi_y)L^2, (2-phi_y)L^2],
    c_z [12, 6L, (4+phi_z)L^2, (2-phi_z)L^2]), c_y = E Iz/((1+phi_y)L^3),
    c_z = E Iy/((1+phi_z)L^3)."""
    P = np.zeros((10, 12, 12))

    def pair(c, i, j, s):             # +s on (i, i), (j, j); -s on (i, j), (j, i)
        P[c, i, i] += s
        P[c, j, j] += s
        P[c, i, j] -= s
        P[c, j, i] -= s

    pair(0, _U, 6 + _U, 1.0)          # axial
    pair(1, _TX, 6 + _TX, 1.0)        # torsion
    for c0, d, r, sg in ((2, _V, _TZ, 1.0), (6, _W, _TY, -1.0)):
        d0, r0, d1, r1 = d, r, 6 + d, 6 + r
        pair(c0, d0, d1, 1.0)                                   # 12 terms
        for (i, j), s in (((d0, r0), sg), ((d0, r1), sg), ((r0, d1), -sg), ((d1, r1), -sg)):
            P[c0 + 1, i, j] = P[c0 + 1, j, i] = s               # 6L terms
        P[c0 + 2, r0, r0] = P[c0 + 2, r1, r1] = 1.0             # (4 + phi) L^2
        P[c0 + 3, r0, r1] = P[c0 + 3, r1, r0] = 1.0             # (2 - phi) L^2
    return P


_P = _patterns()


def _block_rotation(Lam):
    """T = blockdiag(Lam, Lam, Lam, Lam): (E, 12, 12)."""
    E = Lam.shape[0]
    return np.einsum("ab,eij->eaibj", np.eye(4), Lam).reshape(E, 12, 12)


class Frame(ElementType):
    """2-node shear-flexible 3D frame element (see the module docstring)."""
    name = "frame"
    dim = 1
    nodes_per_cell = 2
    dof_names = ("ux", "uy", "uz", "rx", "ry", "rz")
    gmsh_type = 1
    xdmf_type = "Polyline"
    required = ("E", "nu", "rho", "area", "Iy", "Iz", "J")
    optional = {"shear_factor": 5.0 / 6.0, "orientation": (0.0, 0.0, 1.0), "added_mass": 0.0}

    # ------------------------------------------------------------------ checks
    def check(self, X, props):
        """One-line error for bad properties or the first bad cell, else None."""
        for key in ("E", "area", "Iy", "Iz", "J"):
            val = float(getattr(props, key))
            if not val > 0:
                return f"frame: {key} must be > 0 (got {val:g})"
        nu = float(props.nu)
        if not -1.0 < nu <= 0.5:
            return f"frame: nu must be in (-1, 0.5] (got {nu:g})"
        for key in ("rho", "added_mass", "shear_factor"):
            val = float(getattr(props, key))
            if not val >= 0:
                return f"frame: {key} must be >= 0 (got {val:g})"
        if not props.rho * props.area + props.added_mass > 0:
            return "frame: rho * area + added_mass must be > 0 (the lumped mass must be positive)"
        v = np.asarray(props.orientation, dtype=float)
        if v.shape[-1:] != (3,) or v.ndim > 2:
            return f"frame: orientation must be a 3-vector (got shape {v.shape})"
        if not np.all(np.isfinite(v)):
            return f"frame: orientation must be finite (got {v.tolist()})"
        X = np.asarray(X, dtype=float)
        if X.ndim != 3 or X.shape[1:] != (2, 3):
            return f"frame: cells must be (E, 2, 3) coordinates (got shape {X.shape})"
        if X.shape[0] == 0:
            return None
        if v.ndim == 2 and v.shape[0] != X.shape[0]:
            return f"frame: {v.shape[0]} orientation vectors for {X.shape[0]} cells"
        if not np.all(np.isfinite(X)):
            e = int(np.nonzero(~np.isfinite(X).all(axis=(1, 2)))[0][0])
            return f"frame cell {e} has non-finite node coordinates {X[e].tolist()}"
        d = X[:, 1] - X[:, 0]
        L = np.linalg.norm(d, axis=1)
        bad = np.nonzero(L <= 1e-12 * L.max())[0]
        if bad.size:
            e = int(bad[0])
            return (f"frame cell {e} has zero length ({bad.size} such cells): nodes "
                    f"{X[e, 0].tolist()} and {X[e, 1].tolist()}")
        vv = _orientation(props, X.shape[0])
        cr = np.linalg.norm(np.cross(vv, d), axis=1)
        bad = np.nonzero(cr <= 1e-6 * np.linalg.norm(vv, axis=1) * L)[0]
        if bad.size:
            e = int(bad[0])
            return (f"frame cell {e}: orientation {vv[e].tolist()} is parallel to its axis "
                    f"({bad.size} such cells): nodes {X[e, 0].tolist()} and {X[e, 1].tolist()}")
        return None

    def _checked_geometry(self, X, props):
        msg = self.check(X, props)
        if msg:
            raise SSIError(msg)
        return _geometry(X, props)

    # --------------------------------------------------------------- stiffness
    def local_stiffness(self, L, props):
        """Local Timoshenko stiffness (E, 12, 12) of cells of lengths L (vectorised)."""
        E, G, A = float(props.E), float(props.G()), float(props.area)
        Iy, Iz, J = float(props.Iy), float(props.Iz), float(props.J)
        phy = _phi(E, G, Iz, props.shear_factor, A, L)
        phz = _phi(E, G, Iy, props.shear_factor, A, L)
        cy = E * Iz / ((1.0 + phy) * L ** 3)
        cz = E * Iy / ((1.0 + phz) * L ** 3)
        C = np.stack([E * A / L, G * J / L,
                      12 * cy, 6 * L * cy, (4 + phy) * L ** 2 * cy, (2 - phy) * L ** 2 * cy,
                      12 * cz, 6 * L * cz, (4 + phz) * L ** 2 * cz, (2 - phz) * L ** 2 * cz], axis=1)
        return np.einsum("ec,cij->eij", C, _P)

    def stiffness(self, X, props):
        """Element stiffness (E, 12, 12) in global dofs: T^T k T, exactly symmetric."""
        L, Lam = self._checked_geometry(X, props)
        k = self.local_stiffness(L, props)
        T = _block_rotation(Lam)
        K = np.matmul(T.transpose(0, 2, 1), np.matmul(k, T))
        return 0.5 * (K + K.transpose(0, 2, 1))

    # ----------------------------------------------------------- end forces
    def end_force_operator(self, X, props):
        """G (E, 12, 12) with the end forces f = G u_e = k_local (T u_e) of the global element
        dofs u_e (node-major ux uy uz rx ry rz): the forces and moments the nodes exert ON the
        element, in its local axes (x' along the member from node 0 to node 1, y', z' of the
        orientation vector), order (N, V2, V3, T, M2, M3) at node 0 then at node 1, i.e. the
        local dofs (u, v, w, tx, ty, tz); the member's inertia is not included (OpenSees'
        ``localForce``). The stress resultants of the section in the vector convention (the
        force and moment vectors on the face whose outward normal is +x', components along x',
        y', z') are -f[0:6] at node 0 and +f[6:12] at node 1: the axial force (tension > 0) is
        -f[0] = f[6]; the moment about y' (> 0 stretches the +z' fibre, sigma = M2 z' / Iy) is
        -f[4] and f[10]; about z' (> 0 compresses the +y' fibre, sigma = -M3 y' / Iz) -f[5]
        and f[11]; the torque -f[3] and f[9]."""
        L, Lam = self._checked_geometry(X, props)
        return np.matmul(self.local_stiffness(L, props), _block_rotation(Lam))

    def end_forces(self, X, props, ue):
        """End forces (E, 12) of the global element dofs ue (E, 12) (``end_force_operator``)."""
        return np.einsum("eij,ej->ei", self.end_force_operator(X, props), np.asarray(ue, float))

    def local_lumped_mass(self, L, props):
        """HRZ-lumped local diagonal mass (E, 12), dofs (u v w tx ty tz) per node."""
        m = float(props.rho) * float(props.area) + float(props.added_mass)     # kg/m
        rho_r = float(props.rho) + float(props.added_mass) / float(props.area)  # rotary density
        Iy, Iz = float(props.Iy), float(props.Iz)
        mt = m * L / 2.0
        mb = m * L ** 3 / 78.0
        node = np.stack([mt, mt, mt,
                         rho_r * (Iy + Iz) * L / 2.0,
                         mb + rho_r * Iy * L / 2.0,
                         mb + rho_r * Iz * L / 2.0], axis=1)
        return np.concatenate([node, node], axis=1)

    def lumped_mass(self, X, props):
        """Diagonal mass (E, 12) in global dofs: the translations m L / 2 and the
        diagonal of Lam^T diag(local rotational mass) Lam per node."""
        L, Lam = self._checked_geometry(X, props)
        d = self.local_lumped_mass(L, props).reshape(-1, 2, 2, 3)    # (E, node, trans/rot, p)
        out = d.copy()
        out[:, :, 1, :] = np.einsum("epi,eap->eai", Lam ** 2, d[:, :, 1, :])
        return out.reshape(-1, 12)

    # --------------------------------------------------------------- reference
    def stiffness_reference(self, X, props):
        """Slow textbook version: per cell, the local matrix entry by entry
        (McGuire-Gallagher-Ziemian / Przemieniecki table), T written out, T^T k T."""
        X = np.asarray(X, dtype=float)
        msg = self.check(X, props)
        if msg:
            raise SSIError(msg)
        E, G, A = float(props.E), float(props.G()), float(props.area)
        Iy, Iz, J = float(props.Iy), float(props.Iz), float(props.J)
        As = props.shear_factor * A
        vv = _orientation(props, X.shape[0])
        out = np.zeros((X.shape[0], 12, 12))
        for e in range(X.shape[0]):
            d = X[e, 1] - X[e, 0]
            L = np.sqrt(d @ d)
            ex = d / L
            ey = np.cross(vv[e], ex)
            ey = ey / np.sqrt(ey @ ey)
            ez = np.cross(ex, ey)
            py = 12 * E * Iz / (G * As * L ** 2) if As > 0 else 0.0
            pz = 12 * E * Iy / (G * As * L ** 2) if As > 0 else 0.0
            k = np.zeros((12, 12))
            k[0, 0] = E * A / L
            k[0, 6] = -E * A / L
            k[1, 1] = 12 * E * Iz / (L ** 3 * (1 + py))
            k[1, 5] = 6 * E * Iz / (L ** 2 * (1 + py))
            k[1, 7] = -12 * E * Iz / (L ** 3 * (1 + py))
            k[1, 11] = 6 * E * Iz / (L ** 2 * (1 + py))
            k[2, 2] = 12 * E * Iy / (L ** 3 * (1 + pz))
            k[2, 4] = -6 * E * Iy / (L ** 2 * (1 + pz))
            k[2, 8] = -12 * E * Iy / (L ** 3 * (1 + pz))
            k[2, 10] = -6 * E * Iy / (L ** 2 * (1 + pz))
            k[3, 3] = G * J / L
            k[3, 9] = -G * J / L
            k[4, 4] = (4 + pz) * E * Iy / (L * (1 + pz))
            k[4, 8] = 6 * E * Iy / (L ** 2 * (1 + pz))
            k[4, 10] = (2 - pz) * E * Iy / (L * (1 + pz))
            k[5, 5] = (4 + py) * E * Iz / (L * (1 + py))
            k[5, 7] = -6 * E * Iz / (L ** 2 * (1 + py))
            k[5, 11] = (2 - py) * E * Iz / (L * (1 + py))
            k[6, 6] = E * A / L
            k[7, 7] = 12 * E * Iz / (L ** 3 * (1 + py))
            k[7, 11] = -6 * E * Iz / (L ** 2 * (1 + py))
            k[8, 8] = 12 * E * Iy / (L ** 3 * (1 + pz))
            k[8, 10] = 6 * E * Iy / (L ** 2 * (1 + pz))
            k[9, 9] = G * J / L
            k[10, 10] = (4 + pz) * E * Iy / (L * (1 + pz))
            k[11, 11] = (4 + py) * E * Iz / (L * (1 + py))
            for i in range(12):
                for j in range(i):
                    k[i, j] = k[j, i]
            lam = np.array([ex, ey, ez])
            T = np.zeros((12, 12))
            for b in range(4):
                T[3 * b:3 * b + 3, 3 * b:3 * b + 3] = lam
            out[e] = T.T @ k @ T
        return out


FRAME = register(Frame())
