"""4-node flat shell element, 6 dofs per node (ux uy uz rx ry rz, global axes).

Formulation
-----------
A flat facet element in its own plane (local frame below), the sum of two
uncoupled parts (a flat, mid-plane-symmetric element has no membrane-bending
coupling), transformed to global dofs:

* Bending + transverse shear: MITC4, the Reissner-Mindlin quadrilateral with
  the assumed covariant transverse shear of Bathe & Dvorkin, "A four-node plate
  bending element based on Mindlin/Reissner plate theory and a mixed
  interpolation", IJNME 21 (1985) 367-383 (also Dvorkin & Bathe, Eng. Comput.
  1 (1984) 77-88). Chosen over DKQ because it keeps transverse shear
  deformation (the 0.5 m foundation slab on 0.6 m elements is not thin), is
  free of shear locking in the thin limit, has no spurious modes at 2x2
  quadrature, passes the constant-curvature patch test on distorted meshes,
  and is the widely used, well documented basis of many codes' 4-node shells.
* Membrane: the Allman-type quadrilateral with drilling rotations of
  Ibrahimbegovic, Taylor & Wilson, "A robust quadrilateral membrane finite
  element with drilling degrees of freedom", IJNME 30 (1990) 445-457, built
  on the variational principle of Hughes & Brezzi, "On drilling degrees of
  freedom", CMAME 72 (1989) 105-121 (the quadrature is chosen here, see
  below). The drilling rotation is a true rotation: it enters the
  displacement field (quadratic edge modes), so the element represents pure
  in-plane bending of a rectangle (nu = 0) exactly, instead of a bilinear
  membrane plus a fictitious spring, which locks in in-plane bending (MacNeal's
  thin cantilever on 6 rectangles: 0.076 of the reference with the bilinear
  field and this drilling term, 0.904 with the Allman field), the mode that
  the pinched cylinder, the Scordelis-Lo roof and slab-beam joints load.

Local frame and warping
-----------------------
e3 = d1 x d2 / |d1 x d2| with the diagonals d1 = x2 - x0, d2 = x3 - x1;
e1 = the part normal to e3 of g1 = (x1 + x2 - x0 - x3) / 2, normalised;
e2 = e3 x e1. R = [e1; e2; e3] (rows). With c the centroid of the nodes, the
element is computed on the nodes projected onto its mean plane,
p_a = (x_a - c) . (e1, e2), at heights h_a = (x_a - c) . e3 (because e3 is
normal to both diagonals, h_0 = h_2 = -h_1 = -h_3: the warp). The projected
node is joined to the real node by a rigid link (the warping correction of
Taylor, "Finite element analysis of linear shell problems", in Whiteman
(ed.), The Mathematics of Finite Elements and Applications VI, 1988, used
in FEAP's shell elements): u(p_a) = u_a + theta_a x (p_a - x_a) = u_a + h_a e3 x theta_a.
In local components (u' = R u, theta' = R theta) that adds h_a (-theta'_y,
theta'_x, 0) to the in-plane translations, so per node

    [u'_p]   [R   h_a Z R] [u    ]        Z = [[0, -1, 0], [1, 0, 0], [0, 0, 0]]
    [th' ] = [0       R  ] [theta]  = A_a [u; theta],

and K_e = A^T K_flat A (A block diagonal over the nodes). A global rigid
motion u = c + w x x, theta = w is mapped onto the rigid motion c + w x p_a,
theta' = R w of the flat element, which has zero energy in it: the six
rigid-body modes stay exactly in the null space of warped elements too.

Flat element (local x, y; 2x2 Gauss-Legendre unless said)
---------------------------------------------------------
Bilinear N_a(xi, eta) = (1 + xi xi_a)(1 + eta eta_a)/4, isoparametric
geometry, J = [[x,xi, y,xi], [x,eta, y,eta]], [N,x; N,y] = J^-1 [N,xi; N,eta].

Membrane (nodal u_a, v_a, theta_a = local drilling rotation theta'_z):
  u = sum_a N_a u_a + sum_k M_k (theta_j - theta_i) / 8 * l_k n_k
over the edges k = (i, j) = (0,1), (1,2), (2,3), (3,0), M_k the serendipity
mid-side functions (1 at the mid-side of edge k), l_k n_k = (y_j - y_i,
-(x_j - x_i)) the outward normal times the length: the normal mid-side
displacement of a quadratic edge field whose end slopes are the rotations.
  Pi_m = 1/2 int eps^T D_m eps dA + 1/2 gamma t int (skew u - theta)^2 dA,
  eps = (u,x, v,y, u,y + v,x),  skew u = (v,x - u,y)/2,  theta = sum N_a theta_a,
  D_m = E t / (1 - nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu)/2]],
  gamma = drilling * G (Hughes & Brezzi's choice gamma = G; ``drilling`` scales it).
Both terms at 3x3 Gauss points (full integration of the quadratic Allman
field). At 2x2 the element inherits the spurious hourglass mode of the
reduced-integrated 8-node serendipity quad: for rectangles and parallelograms
the membrane then has 4 zero eigenvalues whatever gamma (checked numerically;
near-parallelogram cells get a near-zero one), which a single slab element
between beams would expose. At 3x3 it has exactly the 3 in-plane rigid modes
(the symmetric part alone has one more, u = 0 with equal theta_a, which the
skew term stiffens). The price is a slightly stiffer distorted element in
in-plane bending (MacNeal's thin cantilever, 6 elements: 0.904 rectangles,
0.740 trapezoids, 0.764 parallelograms of the reference with 3x3, against
0.904, 0.782, 0.787 with 2x2); the obstacle-course shells change by < 0.3 %.
Pure in-plane bending of a rectangle costs no skew energy: the Allman field
reproduces u = k x y, v = -k x^2/2 with theta = skew u = -k x, so the penalty
does not lock.

Plate (w_a, theta_x,a, theta_y,a; rotations about local x, y, right hand):
the fibre displacement is z theta x e3 = z (theta_y, -theta_x), so
  kappa = (theta_y,x, -theta_x,y, theta_y,y - theta_x,x),
  gamma = (w,x + theta_y, w,y - theta_x),
  D_b = E t^3 / (12 (1 - nu^2)) [[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu)/2]],
  D_s = shear_factor G t I.
MITC4 shear: the covariant components e_xi = gamma . x,xi = w,xi + theta_y x,xi
- theta_x y,xi and e_eta (same with eta) are computed from the nodal values at
the tying points A (0,-1), C (0,1) (e_xi) and D (-1,0), B (1,0) (e_eta) and
interpolated, e_xi = (1 - eta)/2 e_xi^A + (1 + eta)/2 e_xi^C, e_eta =
(1 - xi)/2 e_eta^D + (1 + xi)/2 e_eta^B; Cartesian gamma = J^-1 (e_xi, e_eta).
A Kirchhoff field (quadratic w, linear rotations, w,x = -theta_y, w,y =
theta_x) has zero tying strains, hence the constant-curvature patch test.

Mass (``lumped_mass``)
----------------------
m_a = rho t, or ``mass_per_area`` when > 0. The area share of node a is the row
sum of the bilinear consistent mass, S_a = sum_b int N_a N_b dA = int N_a dA
(sum_b N_b = 1; positive for any convex quad, exact at 2x2 points), with dA the
projected (mean-plane) area element, sum_a S_a = |d1 x d2| / 2. Translations:
(m_a + added_mass) S_a on ux, uy, uz. Rotations: the rotary inertia of the
section, (m_a + added_mass) t^2/12 S_a, on rx, ry AND rz (the added mass taken as
spread through the thickness like the slab's own, so the rotations are never
massless: the implicit Green's-function integrator needs M > 0 on every free dof). Used isotropically (also about the
normal, where the true drilling inertia is undefined) so that the 3x3
rotational block is (m_a t^2/12 S_a) I in any frame: it stays diagonal in
global dofs whatever the orientation of the shell, and the lumped matrix is
the same in local and global dofs. (With rho = 0, mass_per_area = 0 and no added
mass the element has no mass at all: the parts module refuses such a shell part.)

Pressure (``pressure_forces``): consistent nodal forces f_a = -int p N_a n dA
on the bilinear (possibly warped) surface, n dA = x,xi x x,eta dxi deta.

``stiffness`` is vectorised over cells and Gauss points (einsum/matmul);
``stiffness_reference`` is the slow textbook version (loops over cells and
points, explicit B matrices and 24x24 transformation) it is tested against.
"""
import numpy as np

from . import register
from .base import ElementType

XI_A = np.array([-1.0, 1.0, 1.0, -1.0])
ETA_A = np.array([-1.0, -1.0, 1.0, 1.0])
_G = 1.0 / np.sqrt(3.0)
GAUSS = np.array([[-_G, -_G], [_G, -_G], [_G, _G], [-_G, _G]])     # 2x2, weights 1
TYING = np.array([[0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])  # A, B, C, D
_Z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
MEMBRANE_ORDER = 3                # Gauss order of the membrane (3x3: full for the quadratic Allman field)
MEMBRANE = np.array([0, 1, 5])   # local dofs of node a (u, v, w, thx, thy, thz) in the membrane
PLATE = np.array([2, 3, 4])      # ... and in the plate


def shape(P):
    """Bilinear N (G, 4) and dN/dxi (G, 4, 2) at the points P (G, 2)."""
    xi, eta = P[:, 0:1], P[:, 1:2]
    N = 0.25 * (1 + xi * XI_A) * (1 + eta * ETA_A)
    dN = np.stack([0.25 * XI_A * (1 + eta * ETA_A), 0.25 * ETA_A * (1 + xi * XI_A)], axis=-1)
    return N, dN


def midside(P):
    """Serendipity mid-side functions M (G, 4) of the edges (0,1), (1,2), (2,3), (3,0) and
    dM/dxi (G, 4, 2)."""
    xi, eta = P[:, 0], P[:, 1]
    M = 0.5 * np.stack([(1 - xi ** 2) * (1 - eta), (1 + xi) * (1 - eta ** 2),
                        (1 - xi ** 2) * (1 + eta), (1 - xi) * (1 - eta ** 2)], axis=-1)
    dxi = np.stack([-xi * (1 - eta), 0.5 * (1 - eta ** 2), -xi * (1 + eta), -0.5 * (1 - eta ** 2)], axis=-1)
    deta = np.stack([-0.5 * (1 - xi ** 2), -(1 + xi) * eta, 0.5 * (1 - xi ** 2), -(1 - xi) * eta], axis=-1)
    return M, np.stack([dxi, deta], axis=-1)


def local_frame(X):
    """R (E, 3, 3) rows e1, e2, e3; projected local coordinates (E, 4, 2); heights h (E, 4);
    |d1 x d2| (E,) = twice the projected area. Zero-area cells give a NaN frame."""
    X = np.asarray(X, float)
    n = np.cross(X[:, 2] - X[:, 0], X[:, 3] - X[:, 1])
    a2 = np.linalg.norm(n, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        e3 = n / a2[:, None]
        g1 = 0.5 * (X[:, 1] + X[:, 2] - X[:, 0] - X[:, 3])
        g1 = g1 - np.sum(g1 * e3, axis=1)[:, None] * e3
        e1 = g1 / np.linalg.norm(g1, axis=1)[:, None]
    e2 = np.cross(e3, e1)
    R = np.stack([e1, e2, e3], axis=1)
    d = X - X.mean(axis=1)[:, None, :]
    loc = np.einsum("eij,eaj->eai", R, d)
    return R, loc[:, :, :2], loc[:, :, 2], a2


def _jacobian(xy, dN):
    """J (E, G, 2, 2) with J[k, i] = dx_i/dxi_k, det, inverse."""
    J = np.matmul(dN.transpose(0, 2, 1)[None], xy[:, None])     # sum_a dN[g, a, k] xy[e, a, i]
    det = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
    inv = np.stack([np.stack([J[..., 1, 1], -J[..., 0, 1]], -1),
                    np.stack([-J[..., 1, 0], J[..., 0, 0]], -1)], -2) / det[..., None, None]
    return J, det, inv


def _cartesian(inv, dN):
    """d/dx (E, G, n, 2) from d/dxi (G, n, 2): [d/dx; d/dy] = J^-1 [d/dxi; d/deta]."""
    a, b = dN[None, :, :, 0], dN[None, :, :, 1]
    return np.stack([inv[..., 0, 0, None] * a + inv[..., 0, 1, None] * b,
                     inv[..., 1, 0, None] * a + inv[..., 1, 1, None] * b], axis=-1)


def _props(props):
    E, nu, t = float(props.E), float(props.nu), float(props.thickness)
    G = E / (2 * (1 + nu))
    iso = np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1 - nu)]]) / (1 - nu ** 2)
    k = getattr(props, "shear_factor", 5.0 / 6.0)
    dr = getattr(props, "drilling", 1.0)
    return dict(Dm=E * t * iso, Db=E * t ** 3 / 12.0 * iso, ks=k * G * t, kd=dr * G * t)


def gauss2d(order):
    """Tensor Gauss-Legendre points (G, 2) and weights (G,) on [-1, 1]^2."""
    x, w = np.polynomial.legendre.leggauss(order)
    P = np.array(np.meshgrid(x, x, indexing="ij")).reshape(2, -1).T
    return P, np.outer(w, w).ravel()


def _product(B, D, wd):
    """sum_{g, r, s} B[g, r, i] D[r, s] B[g, s, j] wd[g], batched over cells: (E, n, n)."""
    ne, n = B.shape[0], B.shape[-1]
    return np.matmul(B.reshape(ne, -1, n).transpose(0, 2, 1),
                     (np.matmul(D, B) * wd[:, :, None, None]).reshape(ne, -1, n))


def membrane_B(xy, P):
    """Membrane strain rows at the points P (G, 2): B (E, G, 4, 12) over (u, v, theta_z) per node,
    rows eps_xx, eps_yy, gamma_xy and skew u - theta (the drilling term), and det J (E, G)."""
    ne = xy.shape[0]
    N, dN = shape(P)
    M, dM = midside(P)
    J, det, inv = _jacobian(xy, dN)
    dNx = _cartesian(inv, dN)                                    # (E, G, 4, 2)
    dMx = _cartesian(inv, dM)                                    # (E, G, 4 edges, 2)
    # edge vectors l n / 8 = (dy, -dx) / 8 and the derivatives of the Allman modes of node a:
    # dPhi[e, g, a, c, i] = d(component c of the mode of theta_a)/dx_i; node a ends edge a - 1
    # (sign +) and starts edge a (sign -)
    dxy = np.roll(xy, -1, axis=1) - xy                           # (E, 4 edges, 2)
    ln = np.stack([dxy[..., 1], -dxy[..., 0]], axis=-1) / 8.0
    dPhi = dMx[:, :, :, None, :] * ln[:, None, :, :, None]       # per edge (E, G, k, c, i)
    dPhi = np.roll(dPhi, 1, axis=2) - dPhi                       # per node
    Nx, Ny = dNx[..., 0], dNx[..., 1]
    z = np.zeros_like(Nx)
    # rows eps_xx, eps_yy, gamma_xy, skew u - theta over (node, (u, v, theta_z))
    B = np.stack([np.stack([Nx, z, dPhi[..., 0, 0]], -1),
                  np.stack([z, Ny, dPhi[..., 1, 1]], -1),
                  np.stack([Ny, Nx, dPhi[..., 0, 1] + dPhi[..., 1, 0]], -1),
                  np.stack([-0.5 * Ny, 0.5 * Nx, 0.5 * (dPhi[..., 1, 0] - dPhi[..., 0, 1]) - N[None]], -1)],
                 axis=2).reshape(ne, P.shape[0], 4, 12)
    return B, det


def membrane_stiffness(xy, Dm, kd, rule=None):
    """Allman / Hughes-Brezzi membrane (E, 12, 12) over (u, v, theta_z) per node."""
    P, W = gauss2d(MEMBRANE_ORDER) if rule is None else rule
    B, det = membrane_B(xy, P)
    D = np.zeros((4, 4))
    D[:3, :3], D[3, 3] = Dm, kd
    return _product(B, D, det * W)


def plate_B(xy, P):
    """Plate strain rows at the points P (G, 2): B (E, G, 5, 12) over (w, theta_x, theta_y) per
    node, rows kappa_xx, kappa_yy, 2 kappa_xy (bending) and gamma_xz, gamma_yz (the MITC4
    assumed covariant shear, interpolated from the tying points), and det J (E, G)."""
    ne = xy.shape[0]
    N, dN = shape(P)
    J, det, inv = _jacobian(xy, dN)
    dNx = _cartesian(inv, dN)
    Nx, Ny = dNx[..., 0], dNx[..., 1]
    z = np.zeros_like(Nx)
    Bb = np.stack([np.stack([z, z, Nx], -1),
                   np.stack([z, -Ny, z], -1),
                   np.stack([z, -Nx, Ny], -1)], axis=2).reshape(ne, P.shape[0], 3, 12)
    # MITC4 shear: covariant strains at the tying points, rows over (w, theta_x, theta_y)
    Nt, dNt = shape(TYING)
    Jt = np.einsum("tak,eai->etki", dNt, xy)                      # (E, 4, 2, 2)

    def cov(T, k):
        return np.stack([np.broadcast_to(dNt[T, :, k], (ne, 4)),
                         -Jt[:, T, k, 1, None] * Nt[T], Jt[:, T, k, 0, None] * Nt[T]], -1).reshape(ne, 12)

    eA, eB, eC, eD = cov(0, 0), cov(1, 1), cov(2, 0), cov(3, 1)
    xi, eta = P[:, 0], P[:, 1]
    e_xi = 0.5 * ((1 - eta)[None, :, None] * eA[:, None] + (1 + eta)[None, :, None] * eC[:, None])
    e_eta = 0.5 * ((1 - xi)[None, :, None] * eD[:, None] + (1 + xi)[None, :, None] * eB[:, None])
    Bs = np.matmul(inv, np.stack([e_xi, e_eta], axis=2))         # (E, G, 2, 12)
    return np.concatenate([Bb, Bs], axis=2), det


def plate_stiffness(xy, Db, ks):
    """MITC4 plate (E, 12, 12) over (w, theta_x, theta_y) per node, 2x2 Gauss."""
    B, det = plate_B(xy, GAUSS)
    D = np.zeros((5, 5))
    D[:3, :3], D[3:, 3:] = Db, ks * np.eye(2)
    return _product(B, D, det)                                   # 2x2 weights are 1


RESULTANTS = ("N11", "N22", "N12", "M11", "M22", "M12", "Q1", "Q2")
RESULTANT_UNITS = ("N/m", "N/m", "N/m", "N m/m", "N m/m", "N m/m", "N/m", "N/m")


def resultant_operator(X, props, points=None):
    """S (E, G, 8, 24) with the stress resultants s = S u_e at the points (G, 2) of the reference
    square (default: the centre, G = 1) from the element's global dofs u_e (24, node-major
    ux uy uz rx ry rz), in the element's local frame (``local_frame``: e1, e2 in the mean plane,
    e3 the normal; z the distance along e3 from the mid-surface):

      N11, N22, N12 = int (s11, s22, s12) dz      = D_m eps        [N/m]
      M11, M22, M12 = int (s11, s22, s12) z dz    = D_b kappa      [N m/m]
      Q1,  Q2       = int (s13, s23) dz           = k G t gamma    [N/m]

    with eps (Allman field included), kappa and the MITC4 assumed shear gamma from the same
    B matrices as the stiffness (``membrane_B``, ``plate_B``) on the projected nodes (the
    warping links of ``transformation`` included). M11 > 0 stretches the fibres on the +e3 side
    (the fibre displacement z (theta_y, -theta_x)); Q1 > 0 is the shear on the +e1 face along
    +e3."""
    X = np.asarray(X, float)
    R, xy, h, _ = local_frame(X)
    c = _props(props)
    P = np.zeros((1, 2)) if points is None else np.atleast_2d(np.asarray(points, float))
    Bm, _ = membrane_B(xy, P)
    Bp, _ = plate_B(xy, P)
    ne, ng = X.shape[0], P.shape[0]
    S = np.zeros((ne, ng, 8, 4, 6))
    S[..., 0:3, :, :][..., MEMBRANE] = np.matmul(c["Dm"], Bm[:, :, :3]).reshape(ne, ng, 3, 4, 3)
    S[..., 3:6, :, :][..., PLATE] = np.matmul(c["Db"], Bp[:, :, :3]).reshape(ne, ng, 3, 4, 3)
    S[..., 6:8, :, :][..., PLATE] = c["ks"] * Bp[:, :, 3:].reshape(ne, ng, 2, 4, 3)
    return np.einsum("egrbi,ebij->egrbj", S, transformation(R, h)).reshape(ne, ng, 8, 24)


def resultants(X, props, ue, points=None):
    """Stress resultants (E, G, 8) of the global element dofs ue (E, 24) (``resultant_operator``)."""
    return np.einsum("egri,ei->egr", resultant_operator(X, props, points), np.asarray(ue, float))


def flat_stiffness(xy, props):
    """Stiffness (E, 24, 24) of the flat element on local coordinates xy (E, 4, 2), local dofs
    (u, v, w, theta_x, theta_y, theta_z) per node. Vectorised."""
    c = _props(props)
    im = (np.arange(4)[:, None] * 6 + MEMBRANE).ravel()
    ip = (np.arange(4)[:, None] * 6 + PLATE).ravel()
    K = np.zeros((xy.shape[0], 24, 24))
    K[:, im[:, None], im] = membrane_stiffness(xy, c["Dm"], c["kd"])
    K[:, ip[:, None], ip] = plate_stiffness(xy, c["Db"], c["ks"])
    return K


def transformation(R, h):
    """Per-node blocks A (E, 4, 6, 6): local dofs at the projected node from global dofs."""
    ne = R.shape[0]
    A = np.zeros((ne, 4, 6, 6))
    A[:, :, :3, :3] = R[:, None]
    A[:, :, 3:, 3:] = R[:, None]
    A[:, :, :3, 3:] = h[:, :, None, None] * np.matmul(_Z, R)[:, None]
    return A


def to_global(K, A):
    """A^T K A with A block diagonal over the nodes, given by its blocks A (E, 4, 6, 6)."""
    ne = K.shape[0]
    KA = np.matmul(K.reshape(ne, 24, 4, 6).transpose(0, 2, 1, 3), A)       # (E, b, 24, 6)
    KA = KA.transpose(0, 2, 1, 3).reshape(ne, 4, 6, 24)
    return np.matmul(A.transpose(0, 1, 3, 2), KA).reshape(ne, 24, 24)


def pressure_forces(X, p):
    """Consistent nodal forces (E, 4, 3) of a pressure p (scalar or (E,)) acting against the
    normal (x1 - x0) x (x3 - x0) (traction -p n) on the bilinear surface, 2x2 Gauss."""
    X = np.asarray(X, float)
    N, dN = shape(GAUSS)
    g = np.einsum("gak,eai->egki", dN, X)                        # (E, G, 2, 3)
    n = np.cross(g[:, :, 0], g[:, :, 1])                         # n dA / (dxi deta)
    p = np.broadcast_to(np.asarray(p, float), (X.shape[0],))
    return -p[:, None, None] * np.einsum("ga,egi->eai", N, n)


class Shell(ElementType):
    name = "shell"
    dim = 2
    nodes_per_cell = 4
    dof_names = ("ux", "uy", "uz", "rx", "ry", "rz")
    gmsh_type = 3
    xdmf_type = "Quadrilateral"
    required = ("E", "nu", "rho", "thickness")
    optional = {"shear_factor": 5.0 / 6.0, "added_mass": 0.0, "mass_per_area": 0.0, "drilling": 1.0}

    def check(self, X, props):
        t = float(props.thickness)
        if not t > 0:
            return f"shell thickness must be > 0 (got {t})"
        if not float(props.E) > 0:
            return f"shell Young's modulus must be > 0 (got {props.E})"
        if not -1.0 < float(props.nu) < 0.5:
            return f"shell Poisson's ratio must be in (-1, 0.5) (got {props.nu})"
        if not getattr(props, "shear_factor", 5.0 / 6.0) > 0:
            return ("shell shear_factor must be > 0 (Reissner-Mindlin element; got "
                    f"{props.shear_factor})")
        X = np.asarray(X, float)
        if X.ndim != 3 or X.shape[1:] != (4, 3):
            return f"shell cells need (E, 4, 3) node coordinates, got {X.shape}"
        if X.shape[0] == 0:
            return None
        R, xy, h, a2 = local_frame(X)
        size = np.max(np.linalg.norm(X - X[:, :1], axis=2), axis=1)
        zero = ~(a2 > 1e-12 * size ** 2)
        with np.errstate(invalid="ignore", divide="ignore"):
            _, det, _ = _jacobian(np.nan_to_num(xy), shape(GAUSS)[1])
        bad = zero | np.any(~(det > 1e-12 * size[:, None] ** 2), axis=1)
        if np.any(bad):
            e = int(np.nonzero(bad)[0][0])
            what = "zero area" if zero[e] else "non-positive Jacobian (inverted, bow-tie or degenerate quad)"
            xs = np.array2string(X[e], separator=", ", max_line_width=10 ** 6).replace("\n", "")
            return f"{int(bad.sum())} bad shell cell(s), first: cell {e}, {what}, nodes {xs}"
        return None

    def stiffness(self, X, props):
        R, xy, h, _ = local_frame(X)
        return to_global(flat_stiffness(xy, props), transformation(R, h))

    def lumped_mass(self, X, props):
        _, xy, _, _ = local_frame(X)
        N, dN = shape(GAUSS)
        _, det, _ = _jacobian(xy, dN)
        share = np.einsum("ga,eg->ea", N, det)                   # int N_a dA
        t = float(props.thickness)
        mpa = float(getattr(props, "mass_per_area", 0.0))
        ma = mpa if mpa > 0 else float(props.rho) * t
        mt = (ma + float(getattr(props, "added_mass", 0.0))) * share
        mr = (ma + float(getattr(props, "added_mass", 0.0))) * t ** 2 / 12.0 * share
        return np.concatenate([np.repeat(mt[:, :, None], 3, 2), np.repeat(mr[:, :, None], 3, 2)],
                              axis=2).reshape(-1, 24)

    def stiffness_reference(self, X, props):
        return _stiffness_reference(np.asarray(X, float), props)


def _stiffness_reference(X, props):
    """Slow, explicit version: one cell and one Gauss point at a time."""
    E, nu, t = float(props.E), float(props.nu), float(props.thickness)
    G = E / (2 * (1 + nu))
    k = getattr(props, "shear_factor", 5.0 / 6.0)
    gam = getattr(props, "drilling", 1.0) * G
    C = np.array([[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]]) / (1 - nu ** 2)
    Dm, Db, ks = E * t * C, E * t ** 3 / 12 * C, k * G * t
    g = 1 / np.sqrt(3)
    out = np.zeros((X.shape[0], 24, 24))
    for e in range(X.shape[0]):
        x = X[e]
        # frame
        n = np.cross(x[2] - x[0], x[3] - x[1])
        e3 = n / np.linalg.norm(n)
        v1 = (x[1] + x[2] - x[0] - x[3]) / 2
        v1 = v1 - v1.dot(e3) * e3
        e1 = v1 / np.linalg.norm(v1)
        e2 = np.cross(e3, e1)
        c = x.mean(axis=0)
        px = np.array([(x[a] - c).dot(e1) for a in range(4)])
        py = np.array([(x[a] - c).dot(e2) for a in range(4)])
        hh = np.array([(x[a] - c).dot(e3) for a in range(4)])

        def N_dN(s, r):
            Nn = np.array([(1 - s) * (1 - r), (1 + s) * (1 - r), (1 + s) * (1 + r), (1 - s) * (1 + r)]) / 4
            Ns = np.array([-(1 - r), (1 - r), (1 + r), -(1 + r)]) / 4
            Nr = np.array([-(1 - s), -(1 + s), (1 + s), (1 - s)]) / 4
            return Nn, Ns, Nr

        def jac(Ns, Nr):
            return np.array([[Ns @ px, Ns @ py], [Nr @ px, Nr @ py]])

        def cov_shear(s, r, row):
            """Row (12,) over (w, thx, thy) x 4 of e_xi (row 0) or e_eta (row 1) at (s, r)."""
            Nn, Ns, Nr = N_dN(s, r)
            J = jac(Ns, Nr)
            dk = (Ns, Nr)[row]
            out_ = np.zeros(12)
            for a in range(4):
                out_[3 * a] = dk[a]
                out_[3 * a + 1] = -J[row, 1] * Nn[a]
                out_[3 * a + 2] = J[row, 0] * Nn[a]
            return out_

        eA, eC = cov_shear(0, -1, 0), cov_shear(0, 1, 0)
        eD, eB = cov_shear(-1, 0, 1), cov_shear(1, 0, 1)
        def at(s, r):
            """Shape functions, physical derivatives, |J| and J^-1 at (s, r)."""
            Nn, Ns, Nr = N_dN(s, r)
            J = jac(Ns, Nr)
            Ji = np.linalg.inv(J)
            return Nn, Ji[0, 0] * Ns + Ji[0, 1] * Nr, Ji[1, 0] * Ns + Ji[1, 1] * Nr, np.linalg.det(J), Ji

        Km = np.zeros((12, 12))
        Kp = np.zeros((12, 12))
        pts3, w3 = np.polynomial.legendre.leggauss(MEMBRANE_ORDER)
        for i3 in range(len(w3)):
            for j3 in range(len(w3)):
                s, r, wt = pts3[i3], pts3[j3], w3[i3] * w3[j3]
                Nn, Nx, Ny, detJ, Ji = at(s, r)
                # mid-side functions of edges 0-1, 1-2, 2-3, 3-0 and their xi, eta derivatives
                Ms = [-s * (1 - r), (1 - r * r) / 2, -s * (1 + r), -(1 - r * r) / 2]
                Mr = [-(1 - s * s) / 2, -(1 + s) * r, (1 - s * s) / 2, -(1 - s) * r]
                Bm = np.zeros((3, 12))
                bsk = np.zeros(12)
                for a in range(4):
                    # Allman mode of theta_a: sum over the two edges of node a
                    dux = duy = dvx = dvy = 0.0
                    for kk, (i, j) in enumerate(((0, 1), (1, 2), (2, 3), (3, 0))):
                        if a not in (i, j):
                            continue
                        sgn = 1.0 if a == j else -1.0
                        Mx = Ji[0, 0] * Ms[kk] + Ji[0, 1] * Mr[kk]
                        My = Ji[1, 0] * Ms[kk] + Ji[1, 1] * Mr[kk]
                        lnx, lny = (py[j] - py[i]) / 8, -(px[j] - px[i]) / 8
                        dux += sgn * Mx * lnx
                        duy += sgn * My * lnx
                        dvx += sgn * Mx * lny
                        dvy += sgn * My * lny
                    Bm[:, 3 * a:3 * a + 3] = [[Nx[a], 0, dux], [0, Ny[a], dvy], [Ny[a], Nx[a], duy + dvx]]
                    bsk[3 * a:3 * a + 3] = [-Ny[a] / 2, Nx[a] / 2, (dvx - duy) / 2 - Nn[a]]
                Km += (Bm.T @ Dm @ Bm + gam * t * np.outer(bsk, bsk)) * detJ * wt
        for s, r in ((-g, -g), (g, -g), (g, g), (-g, g)):
            Nn, Nx, Ny, detJ, Ji = at(s, r)
            Bb = np.zeros((3, 12))
            for a in range(4):
                Bb[:, 3 * a:3 * a + 3] = [[0, 0, Nx[a]], [0, -Ny[a], 0], [0, -Nx[a], Ny[a]]]
            exi = (1 - r) / 2 * eA + (1 + r) / 2 * eC
            eeta = (1 - s) / 2 * eD + (1 + s) / 2 * eB
            Bs = Ji @ np.vstack([exi, eeta])
            Kp += (Bb.T @ Db @ Bb + ks * Bs.T @ Bs) * detJ
        Kl = np.zeros((24, 24))
        for a in range(4):
            for b in range(4):
                for ii, pi in enumerate((0, 1, 5)):
                    for jj, pj in enumerate((0, 1, 5)):
                        Kl[6 * a + pi, 6 * b + pj] = Km[3 * a + ii, 3 * b + jj]
                for ii, pi in enumerate((2, 3, 4)):
                    for jj, pj in enumerate((2, 3, 4)):
                        Kl[6 * a + pi, 6 * b + pj] = Kp[3 * a + ii, 3 * b + jj]
        # 24x24 transformation: rotation to local, then rigid link to the mean plane
        R = np.vstack([e1, e2, e3])
        T = np.zeros((24, 24))
        for a in range(4):
            T[6 * a:6 * a + 3, 6 * a:6 * a + 3] = R
            T[6 * a + 3:6 * a + 6, 6 * a + 3:6 * a + 6] = R
            L = np.eye(6)
            L[0, 4] = -hh[a]         # u'_p = u' - h theta'_y
            L[1, 3] = hh[a]          # v'_p = v' + h theta'_x
            T[6 * a:6 * a + 6, 6 * a:6 * a + 6] = L @ T[6 * a:6 * a + 6, 6 * a:6 * a + 6]
        out[e] = T.T @ Kl @ T
    return out


SHELL = register(Shell())
